//! The sim world's `changes` section: semi-static objects (pallets left in an aisle, a
//! blocked dock lane) that appear in a zone and vanish again, each zone at its own
//! rate. Where a warehouse's news comes from: a few hot zones change often, most
//! rarely, and a fleet that learns which is which finds the news first.
//!
//! ```yaml
//! changes:
//!   - { name: dock-lanes, rect: [8.0, 1.0, 52.0, 5.0], size_m: [1.2, 1.0],
//!       appear_per_hour: 8.0, mean_stay_s: 900.0, max_present: 3 }
//! ```
//!
//! **The process (roam's choice; no paper describes one).** Each zone holds at most
//! `max_present` objects. At every sim step of `dt` seconds, a zone with room starts an
//! object with probability `1 − exp(−appear_per_hour · dt / 3600)` (a Poisson process
//! of appearances, thinned while the zone is full), its centre uniform in `rect`, on a
//! place where its footprint covers no wall, no other object and no robot (a few draws,
//! else no object this step); it stays an exponential time of mean `mean_stay_s`, then
//! vanishes. A cell of the zone therefore turns occupied and free again at rates that
//! differ by zone: the two Poisson processes of paper 004 §3 per cell, with rates the
//! mapper can learn.

use serde::Deserialize;

use super::field_issue::FieldIssue;

/// Zones in one scenario at most (limit `changes`).
pub const MAX_CHANGE_ZONES: usize = 256;
/// Objects one zone holds at once at most (limit `max_present`).
pub const MAX_PRESENT_PER_ZONE: u32 = 64;
/// The highest appearance rate, per hour (limit `appear_per_hour`): one a second.
pub const MAX_APPEAR_PER_HOUR: f64 = 3600.0;

/// One zone where objects appear and vanish.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChangeZoneSpec {
    pub name: String,
    /// Where an object's centre may fall: x0, y0, x1, y1 in world metres.
    pub rect: [f64; 4],
    /// The object's width and height, metres (rounded to whole cells, at least one).
    pub size_m: [f64; 2],
    /// Appearances per hour while the zone has room (≥ 0; 0: nothing ever appears).
    pub appear_per_hour: f64,
    /// The mean time an object stays, seconds (> 0).
    pub mean_stay_s: f64,
    /// Objects in the zone at once at most (1..=[`MAX_PRESENT_PER_ZONE`]).
    pub max_present: u32,
}

impl ChangeZoneSpec {
    /// The probability that a zone with room starts an object in a step of `dt_s`.
    pub fn appear_probability(&self, dt_s: f64) -> f64 {
        -(-self.appear_per_hour * dt_s / 3600.0).exp_m1()
    }
}

/// Checks the section: names, rates, sizes and that each rect lies on the map
/// (`extent`: x0, y0, x1, y1 of the map in metres).
pub fn check(zones: &[ChangeZoneSpec], extent: [f64; 4]) -> Result<(), FieldIssue> {
    if zones.len() > MAX_CHANGE_ZONES {
        return Err(FieldIssue::new(
            "changes",
            format!("{} zones; the limit is {MAX_CHANGE_ZONES}", zones.len()),
        ));
    }
    for (i, z) in zones.iter().enumerate() {
        let f = |name: &str| format!("changes[{i}].{name}");
        if z.name.is_empty() {
            return Err(FieldIssue::new(f("name"), "a name must not be empty"));
        }
        if zones[..i].iter().any(|o| o.name == z.name) {
            return Err(FieldIssue::new(
                f("name"),
                format!("the name '{}' is used twice in changes", z.name),
            ));
        }
        if !(z.appear_per_hour.is_finite()
            && (0.0..=MAX_APPEAR_PER_HOUR).contains(&z.appear_per_hour))
        {
            return Err(FieldIssue::new(
                f("appear_per_hour"),
                format!(
                    "zone '{}': must be a rate in 0..={MAX_APPEAR_PER_HOUR} per hour, got {}",
                    z.name, z.appear_per_hour
                ),
            ));
        }
        if !(z.mean_stay_s.is_finite() && z.mean_stay_s > 0.0) {
            return Err(FieldIssue::new(
                f("mean_stay_s"),
                format!(
                    "zone '{}': must be a positive number of seconds, got {}",
                    z.name, z.mean_stay_s
                ),
            ));
        }
        if !(1..=MAX_PRESENT_PER_ZONE).contains(&z.max_present) {
            return Err(FieldIssue::new(
                f("max_present"),
                format!(
                    "zone '{}': must be 1..={MAX_PRESENT_PER_ZONE}, got {}",
                    z.name, z.max_present
                ),
            ));
        }
        if !z.size_m.iter().all(|s| s.is_finite() && *s > 0.0) {
            return Err(FieldIssue::new(
                f("size_m"),
                format!(
                    "zone '{}': must be two positive numbers of metres, got {:?}",
                    z.name, z.size_m
                ),
            ));
        }
        let [x0, y0, x1, y1] = z.rect;
        let [mx0, my0, mx1, my1] = extent;
        let inside = z.rect.iter().all(|v| v.is_finite())
            && x0 < x1
            && y0 < y1
            && x0 >= mx0
            && y0 >= my0
            && x1 <= mx1
            && y1 <= my1;
        if !inside {
            return Err(FieldIssue::new(
                f("rect"),
                format!(
                    "zone '{}': [{x0}, {y0}, {x1}, {y1}] must be x0 < x1, y0 < y1, on the \
                     map (x {mx0}..{mx1}, y {my0}..{my1} m)",
                    z.name
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn zone() -> ChangeZoneSpec {
        ChangeZoneSpec {
            name: "dock".into(),
            rect: [1.0, 1.0, 5.0, 3.0],
            size_m: [1.2, 1.0],
            appear_per_hour: 6.0,
            mean_stay_s: 600.0,
            max_present: 2,
        }
    }

    const MAP: [f64; 4] = [0.0, 0.0, 10.0, 10.0];

    #[test]
    fn a_good_zone_passes_and_each_bad_field_is_named() {
        assert_eq!(check(&[zone()], MAP), Ok(()));
        let named = |z: ChangeZoneSpec, field: &str| {
            let issue = check(&[z], MAP).expect_err("refused");
            assert_eq!(issue.field, format!("changes[0].{field}"), "{issue:?}");
        };
        named(
            ChangeZoneSpec {
                appear_per_hour: -1.0,
                ..zone()
            },
            "appear_per_hour",
        );
        named(
            ChangeZoneSpec {
                appear_per_hour: f64::NAN,
                ..zone()
            },
            "appear_per_hour",
        );
        named(
            ChangeZoneSpec {
                mean_stay_s: 0.0,
                ..zone()
            },
            "mean_stay_s",
        );
        named(
            ChangeZoneSpec {
                max_present: 0,
                ..zone()
            },
            "max_present",
        );
        named(
            ChangeZoneSpec {
                rect: [1.0, 1.0, 11.0, 3.0],
                ..zone()
            },
            "rect",
        );
        named(
            ChangeZoneSpec {
                size_m: [0.0, 1.0],
                ..zone()
            },
            "size_m",
        );
        let twice = check(&[zone(), zone()], MAP).expect_err("refused");
        assert_eq!(twice.field, "changes[1].name");
    }

    #[test]
    fn the_appearance_probability_is_the_poisson_rate_over_a_step() {
        let z = zone();
        // 6 an hour over 0.4 s: 1 − e^(−6·0.4/3600).
        let p = z.appear_probability(0.4);
        assert!((p - (1.0 - (-6.0f64 * 0.4 / 3600.0).exp())).abs() < 1e-15);
        assert_eq!(
            ChangeZoneSpec {
                appear_per_hour: 0.0,
                ..z
            }
            .appear_probability(0.4),
            0.0
        );
    }
}
