//! Replacement libraries for 3D-printed stop-motion (StopShop, Abdrashitov et al.).
//!
//! Two concerns, two modules: [`segment`] (part segmentation and seam homogenization,
//! Sections 3.1–3.2) and [`library`] (replacement library and per-frame labels, fabrication,
//! Sections 3.3–3.4, 5).

pub mod library;
pub mod segment;
