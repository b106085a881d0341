//! roam's localization algorithm (paper 002 §2, Lite & Rinner): TOA ranging with
//! distance-dependent noise, the weighted least-squares position estimate, the Fisher
//! information matrix, the Cramér–Rao bound and the position error bound, at a point,
//! at a list of points and over a grid region.
//!
//! Plain Rust over plain types: no Zenoh, no async. The service adapter, the controller's
//! experiments and the benchmark runner call the same entry points:
//! [`Tracker::on_scan`] (one position fix per range scan, from the robot's last fix),
//! [`estimate`] (one position fix) and [`peb_field`] (a PEB layer).

pub mod error;
pub mod field;
pub mod fim;
pub mod model;
pub mod service;
pub mod tracker;
pub mod wls;

pub use error::LocalizationError;
pub use field::{
    bounds_at, crb_field, peb_field, peb_gradient, CrbField, GridRegion, PebField,
    DEFAULT_GRADIENT_STEP_M,
};
pub use fim::{bound, bound_from_fim, fim, Bound, FimOptions, MIN_FIX_ANCHORS};
pub use model::RangingModel;
pub use nalgebra;
pub use roam_world::noise::ToaNoise;
pub use tracker::Tracker;
pub use wls::{estimate, Degraded, Estimate, Range, WlsOptions};
