//! raymarch (in progress)
