//! The three forces of paper 002 §3 and their weighted sum, the command u of Eq. 3.

use crate::information::InformationField;
use crate::obstacle_field::{unit, ObstacleField};
use crate::params::ApfParams;
use crate::weights::is_weight;

/// The smallest η the repulsive force is evaluated at, metres: Khatib's force grows as
/// 1/η³ and is infinite at an obstacle's face; below 1 cm it is held at its 1 cm value
/// (20 · (100 − 1/3) · 10⁴ ≈ 2·10⁷ with paper 002's z_r), which still dwarfs every other
/// force, and the sim clips the move to its top speed anyway.
pub const MIN_ETA_M: f64 = 0.01;

/// The attractive force f_a (paper 002 §3): the unit vector from `p` to `waypoint`; zero
/// at the waypoint. A unit vector, not the gradient of a quadratic potential, so the
/// robot approaches at a constant commanded speed and z_a, z_r and z_is are directly
/// comparable (paper 002's ES1 robot drove 59.56 m in 296 steps of μ = 0.2: full-length
/// steps all the way).
pub fn attractive(p: [f64; 2], waypoint: [f64; 2]) -> [f64; 2] {
    unit([waypoint[0] - p[0], waypoint[1] - p[1]])
}

/// Khatib's repulsive force [10] for an obstacle at distance `eta_m` in direction
/// `away` (a unit vector pointing from the obstacle to the robot):
/// (1/η − 1/η_thres) · (1/η²) · away for η < η_thres, zero beyond (paper 002 §4:
/// η_thres = 3 m). η is held at [`MIN_ETA_M`] or more.
pub fn repulsive_from(eta_m: f64, away: [f64; 2], eta_thres_m: f64) -> [f64; 2] {
    // NaN counts as beyond the range.
    if eta_m.is_nan() || eta_m >= eta_thres_m {
        return [0.0, 0.0];
    }
    let eta = eta_m.max(MIN_ETA_M);
    let magnitude = (1.0 / eta - 1.0 / eta_thres_m) / (eta * eta);
    [magnitude * away[0], magnitude * away[1]]
}

/// f_Tr at `p`: the repulsion of the nearest obstacle of `field` ([`repulsive_from`]).
/// The paper's "cumulative" repulsive force sums over obstacles; roam uses the nearest
/// obstacle cell only (the distance field's), the usual grid-map reading, so a long wall
/// pushes like one obstacle rather than like each of its cells.
pub fn repulsive(field: &ObstacleField, p: [f64; 2], eta_thres_m: f64) -> [f64; 2] {
    let eta = field.distance_m(p);
    if eta.is_nan() || eta >= eta_thres_m {
        return [0.0, 0.0];
    }
    repulsive_from(eta, field.away(p), eta_thres_m)
}

/// The unsigned angle ω between `f_a` and `f_is`, degrees in 0..=180 (paper 002 Eq. 2);
/// 0 when either is zero (undefined).
pub fn omega_deg(f_a: [f64; 2], f_is: [f64; 2]) -> f64 {
    let na = f_a[0].hypot(f_a[1]);
    let ni = f_is[0].hypot(f_is[1]);
    if !(na > 0.0 && ni > 0.0 && na.is_finite() && ni.is_finite()) {
        return 0.0;
    }
    let cross = f_a[0] * f_is[1] - f_a[1] * f_is[0];
    let dot = f_a[0] * f_is[0] + f_a[1] * f_is[1];
    cross.abs().atan2(dot).to_degrees()
}

/// The forces at one point and the command they make.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Forces {
    pub attractive: [f64; 2],
    pub repulsive: [f64; 2],
    pub information: [f64; 2],
    /// ω between f_a and f_is, degrees.
    pub omega_deg: f64,
    /// z_isa(ω) (paper 002 Eq. 2).
    pub z_isa: f64,
    /// u = z_a f_a + z_r f_Tr + z_isa(ω) f_is (paper 002 Eq. 3).
    pub u: [f64; 2],
}

/// Paper 002 Eq. 3 from the three forces already evaluated.
pub fn combine(
    params: &ApfParams,
    attractive: [f64; 2],
    repulsive: [f64; 2],
    information: [f64; 2],
) -> Forces {
    let omega = omega_deg(attractive, information);
    let z_isa = is_weight(
        params.scheme,
        params.z_is,
        omega,
        params.omega_t_deg,
        params.cutoff_keep,
    );
    let u = std::array::from_fn(|k| {
        params.z_a * attractive[k] + params.z_r * repulsive[k] + z_isa * information[k]
    });
    Forces {
        attractive,
        repulsive,
        information,
        omega_deg: omega,
        z_isa,
        u,
    }
}

/// The forces at `p` toward `waypoint` and the command u (paper 002 Eq. 3). The IS force
/// is not evaluated at all under the plain scheme (its weight is 0 there).
pub fn command(
    params: &ApfParams,
    obstacles: &ObstacleField,
    information: &InformationField,
    p: [f64; 2],
    waypoint: [f64; 2],
) -> Forces {
    let f_a = attractive(p, waypoint);
    let f_r = repulsive(obstacles, p, params.eta_thres_m);
    let f_is = match params.scheme {
        crate::weights::Scheme::Plain => [0.0, 0.0],
        _ => information.is_force(p),
    };
    combine(params, f_a, f_r, f_is)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weights::Scheme;

    fn close(a: f64, b: f64) {
        assert!((a - b).abs() < 1e-12, "{a} != {b}");
    }

    #[test]
    fn the_attractive_force_is_a_unit_vector_to_the_waypoint() {
        let f = attractive([1.0, 1.0], [4.0, 5.0]);
        close(f[0], 0.6);
        close(f[1], 0.8);
        assert_eq!(attractive([2.0, 3.0], [2.0, 3.0]), [0.0, 0.0]);
    }

    #[test]
    fn the_repulsive_force_follows_khatib() {
        // η = 1: (1 − 1/3) · 1 = 2/3.
        let f = repulsive_from(1.0, [0.0, 1.0], 3.0);
        close(f[0], 0.0);
        close(f[1], 2.0 / 3.0);
        // η = 2: (1/2 − 1/3)/4 = 1/24, along (−0.6, 0.8).
        let f = repulsive_from(2.0, [-0.6, 0.8], 3.0);
        close(f[0], -0.6 / 24.0);
        close(f[1], 0.8 / 24.0);
        // At and beyond η_thres: nothing.
        assert_eq!(repulsive_from(3.0, [1.0, 0.0], 3.0), [0.0, 0.0]);
        assert_eq!(repulsive_from(7.0, [1.0, 0.0], 3.0), [0.0, 0.0]);
        // At the face: held at 1 cm, (100 − 1/3) · 10⁴.
        let f = repulsive_from(0.0, [1.0, 0.0], 3.0);
        assert!((f[0] - (100.0 - 1.0 / 3.0) * 1e4).abs() < 1e-6);
    }

    #[test]
    fn omega_is_the_unsigned_angle_in_degrees() {
        close(omega_deg([1.0, 0.0], [1.0, 0.0]), 0.0);
        close(omega_deg([1.0, 0.0], [0.0, 1.0]), 90.0);
        close(omega_deg([1.0, 0.0], [0.0, -2.0]), 90.0);
        close(omega_deg([1.0, 0.0], [-1.0, -1.0]), 135.0);
        close(omega_deg([1.0, 0.0], [-1.0, 0.0]), 180.0);
        close(omega_deg([0.0, 0.0], [-1.0, 0.0]), 0.0);
        close(omega_deg([1.0, 0.0], [0.0, 0.0]), 0.0);
    }

    #[test]
    fn the_command_is_the_weighted_sum_of_eq_3() {
        let params = ApfParams {
            scheme: Scheme::Linear,
            z_is: 0.8,
            ..ApfParams::default()
        };
        // f_a = +x, f_Tr = (0, 1/24), f_is at 135°: z_isa = 0.8 · 45/90 = 0.4.
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let f = combine(&params, [1.0, 0.0], [0.0, 1.0 / 24.0], [-s, s]);
        close(f.omega_deg, 135.0);
        close(f.z_isa, 0.4);
        close(f.u[0], 1.0 - 0.4 * s);
        close(f.u[1], 20.0 / 24.0 + 0.4 * s);
        // Fixed keeps 0.8 whatever the angle; plain drops the IS force.
        let fixed = combine(
            &ApfParams {
                scheme: Scheme::Fixed,
                ..params.clone()
            },
            [1.0, 0.0],
            [0.0, 0.0],
            [-1.0, 0.0],
        );
        close(fixed.u[0], 0.2);
        let plain = combine(
            &ApfParams {
                scheme: Scheme::Plain,
                ..params
            },
            [1.0, 0.0],
            [0.0, 0.0],
            [0.0, 1.0],
        );
        assert_eq!(plain.u, [1.0, 0.0]);
        close(plain.z_isa, 0.0);
    }
}
