//! A plan's work in units, and the instance's measured seconds per unit.

/// The units of what every plan does besides the GA's generations.
pub const OVERHEAD_UNITS: f64 = 2.0e6;
/// The seconds per unit one plan alone takes, as an instance assumes before its first
/// plan ends: 10 ns, about what the paper's workload measures on a 2-core machine
/// (Model I, 0.2 m cells). Its plans share the cores, so the instance starts from this
/// times `max_concurrent_plans`.
pub const PRIOR_SECONDS_PER_UNIT: f64 = 1.0e-8;
/// The weight of the newest measurement in the rate's average.
pub const RATE_WEIGHT: f64 = 0.3;

/// Seconds per unit of plan work, measured (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rate {
    pub seconds_per_unit: f64,
    pub samples: u64,
}

impl Default for Rate {
    fn default() -> Self {
        Rate {
            seconds_per_unit: PRIOR_SECONDS_PER_UNIT,
            samples: 0,
        }
    }
}

impl Rate {
    /// Takes a plan that did `units` of work in `seconds` of wall time.
    pub fn measure(&mut self, units: f64, seconds: f64) {
        if !(units.is_finite() && units > 0.0 && seconds.is_finite() && seconds >= 0.0) {
            return;
        }
        let measured = seconds / units;
        self.seconds_per_unit = if self.samples == 0 {
            measured
        } else {
            RATE_WEIGHT * measured + (1.0 - RATE_WEIGHT) * self.seconds_per_unit
        };
        self.samples += 1;
    }
}

/// The units of a plan whose GA costs `cost` ([`crate::limits::PlanSize::cost`]; 0
/// for a plan without generations).
pub fn units(cost: u64) -> f64 {
    OVERHEAD_UNITS + cost as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rate_learns_from_what_plans_took() {
        let mut rate = Rate::default();
        rate.measure(1e8, 2.0);
        assert!((rate.seconds_per_unit - 2e-8).abs() < 1e-20);
        rate.measure(1e8, 1.0);
        assert!((rate.seconds_per_unit - (0.3 * 1e-8 + 0.7 * 2e-8)).abs() < 1e-20);
        rate.measure(0.0, 1.0);
        rate.measure(1e8, f64::NAN);
        assert_eq!(rate.samples, 2);
    }
}
