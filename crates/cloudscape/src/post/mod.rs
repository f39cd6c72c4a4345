//! Post-processing of HDR frames: exposure, tone mapping and display encoding.

pub mod tonemap;
