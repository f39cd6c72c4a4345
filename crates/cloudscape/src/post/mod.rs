//! post (in progress)
