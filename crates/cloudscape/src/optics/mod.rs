//! optics (in progress)
