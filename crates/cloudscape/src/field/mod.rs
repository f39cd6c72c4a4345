//! field (in progress)
