//! The evaluation metrics of paper 000 §III, computed on the true information map.

use crate::params::GaParams;
use crate::world::{Cell, World};

/// U_ges, D and the information of the distinct cells seen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathMetrics {
    /// Eq. 11: Σ over genes of the window sum of I. A cell in view at several genes is
    /// counted each time, as the paper defines it.
    pub u_ges: f64,
    /// Eq. 12: U_ges / L, L the number of genes.
    pub density: f64,
    /// Σ I over the distinct cells seen: what the robot actually learns.
    pub distinct_information: f64,
}

pub fn path_metrics(world: &World, params: &GaParams, path: &[Cell]) -> PathMetrics {
    let window = params.window();
    let (w, h) = (world.width() as i32, world.height() as i32);
    let mut seen = vec![false; world.cell_count()];
    let mut u_ges = 0.0;
    let mut distinct = 0.0;
    for &cell in path {
        let (x, y) = world.xy(cell);
        for &(dx, dy) in &window {
            let (nx, ny) = (x as i32 + dx, y as i32 + dy);
            if nx < 0 || ny < 0 || nx >= w || ny >= h {
                continue;
            }
            let idx = (ny * w + nx) as usize;
            let score = f64::from(world.information[idx]);
            u_ges += score;
            if !seen[idx] {
                seen[idx] = true;
                distinct += score;
            }
        }
    }
    let density = if path.is_empty() {
        0.0
    } else {
        u_ges / path.len() as f64
    };
    PathMetrics {
        u_ges,
        density,
        distinct_information: distinct,
    }
}
