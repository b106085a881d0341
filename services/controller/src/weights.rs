//! The information-seeking weight z_isa(ω) of paper 002 Eq. 2: how strongly the IS force
//! pulls, given the angle ω between the attractive and the IS force.

use serde::{Deserialize, Serialize};

/// How the information-seeking weight adapts to ω (paper 002 §3.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Scheme {
    /// Traditional APF: no IS force at all (weight 0 at every ω).
    Plain,
    /// IS with the constant weight z_is at every ω (paper 002's "fixed", from [9]).
    Fixed,
    /// z_is up to ω_t, `cutoff_keep · z_is` above (paper 002 Eq. 2 with `cutoff_keep` 0).
    Cutoff,
    /// z_is up to ω_t, then falling linearly to 0 at 180° (paper 002 Eq. 2).
    Linear,
    /// z_is up to ω_t, z_is · sin|ω| above (paper 002 Eq. 2).
    Sinusoidal,
}

impl Scheme {
    /// Every scheme, in the order paper 002 reports them.
    pub const ALL: [Scheme; 5] = [
        Scheme::Plain,
        Scheme::Fixed,
        Scheme::Cutoff,
        Scheme::Linear,
        Scheme::Sinusoidal,
    ];

    /// The schemes with an IS force (paper 002 ES2 varies z_is for these).
    pub const IS: [Scheme; 4] = [
        Scheme::Fixed,
        Scheme::Cutoff,
        Scheme::Linear,
        Scheme::Sinusoidal,
    ];

    /// The name used in configs and reports.
    pub fn name(self) -> &'static str {
        match self {
            Scheme::Plain => "plain",
            Scheme::Fixed => "fixed",
            Scheme::Cutoff => "cutoff",
            Scheme::Linear => "linear",
            Scheme::Sinusoidal => "sinusoidal",
        }
    }
}

impl std::fmt::Display for Scheme {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// z_isa(ω) of paper 002 Eq. 2 for the unsigned angle `omega_deg` (degrees, 0..=180)
/// between f_a and f_is: z_is for |ω| ≤ ω_t under every IS scheme; above ω_t,
/// `cutoff_keep · z_is` (cutoff), z_is · (180 − |ω|)/(180 − ω_t) (linear),
/// z_is · sin|ω| (sinusoidal); z_is at every angle (fixed); 0 at every angle (plain).
///
/// A non-finite ω counts as 0° (the forces are then undefined, see
/// [`crate::forces::omega_deg`]).
pub fn is_weight(
    scheme: Scheme,
    z_is: f64,
    omega_deg: f64,
    omega_t_deg: f64,
    cutoff_keep: f64,
) -> f64 {
    let omega = if omega_deg.is_finite() {
        omega_deg.abs().min(180.0)
    } else {
        0.0
    };
    match scheme {
        Scheme::Plain => 0.0,
        Scheme::Fixed => z_is,
        _ if omega <= omega_t_deg => z_is,
        Scheme::Cutoff => cutoff_keep * z_is,
        // ω > ω_t here, so 180 − ω_t > 0.
        Scheme::Linear => z_is * (180.0 - omega) / (180.0 - omega_t_deg),
        Scheme::Sinusoidal => z_is * omega.to_radians().sin(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const Z: f64 = 0.8;
    const T: f64 = 90.0;

    fn w(s: Scheme, omega: f64) -> f64 {
        is_weight(s, Z, omega, T, 0.0)
    }

    fn close(a: f64, b: f64) {
        assert!((a - b).abs() < 1e-12, "{a} != {b}");
    }

    #[test]
    fn plain_never_seeks_information() {
        for omega in [0.0, 90.0, 90.001, 135.0, 180.0] {
            close(w(Scheme::Plain, omega), 0.0);
        }
    }

    #[test]
    fn fixed_is_z_is_everywhere() {
        for omega in [0.0, 90.0, 90.001, 135.0, 180.0] {
            close(w(Scheme::Fixed, omega), 0.8);
        }
    }

    #[test]
    fn cutoff_drops_to_the_kept_share_above_the_threshold() {
        close(w(Scheme::Cutoff, 0.0), 0.8);
        close(w(Scheme::Cutoff, 90.0), 0.8);
        close(w(Scheme::Cutoff, 90.001), 0.0);
        close(w(Scheme::Cutoff, 135.0), 0.0);
        close(w(Scheme::Cutoff, 180.0), 0.0);
        // Keeping 25 %: 0.25 · 0.8 = 0.2.
        close(is_weight(Scheme::Cutoff, Z, 135.0, T, 0.25), 0.2);
    }

    #[test]
    fn linear_falls_to_zero_at_180() {
        close(w(Scheme::Linear, 0.0), 0.8);
        close(w(Scheme::Linear, 90.0), 0.8);
        // 0.8 · (180 − 90.9)/90 = 0.8 · 0.99 = 0.792.
        close(w(Scheme::Linear, 90.9), 0.792);
        // 0.8 · 45/90 = 0.4.
        close(w(Scheme::Linear, 135.0), 0.4);
        close(w(Scheme::Linear, 180.0), 0.0);
        // ω_t = 120: at 150°, 0.8 · 30/60 = 0.4.
        close(is_weight(Scheme::Linear, Z, 150.0, 120.0, 0.0), 0.4);
    }

    #[test]
    fn sinusoidal_follows_the_sine_above_the_threshold() {
        close(w(Scheme::Sinusoidal, 0.0), 0.8);
        close(w(Scheme::Sinusoidal, 90.0), 0.8);
        // sin(90.9°) = cos(0.9°) = 0.999876632...
        close(
            w(Scheme::Sinusoidal, 90.9),
            0.8 * 0.9_f64.to_radians().cos(),
        );
        // sin 135° = √2/2.
        close(
            w(Scheme::Sinusoidal, 135.0),
            0.8 * std::f64::consts::FRAC_1_SQRT_2,
        );
        assert!(w(Scheme::Sinusoidal, 180.0).abs() < 1e-15);
    }

    #[test]
    fn the_sign_of_omega_does_not_matter_and_nan_counts_as_zero() {
        close(w(Scheme::Linear, -135.0), 0.4);
        close(w(Scheme::Cutoff, f64::NAN), 0.8);
    }

    #[test]
    fn schemes_serialize_in_snake_case() {
        assert_eq!(
            serde_json::to_string(&Scheme::Sinusoidal).ok().as_deref(),
            Some("\"sinusoidal\"")
        );
        assert_eq!(Scheme::Cutoff.to_string(), "cutoff");
    }
}
