//! Semi-static objects: pallets and obstacles that appear in a zone and vanish again
//! (the scenario's `changes` section, `roam_world::scenario::changes`, where the
//! process is written down).
//!
//! **Common random numbers.** The objects' schedule (when each zone starts one, where,
//! for how long) comes from a stream of its own and never from where the robots are:
//! every step draws one number per zone, and a zone that starts an object draws its
//! candidate places and its stay, whatever happens next. So two runs of a scenario with
//! the same seed draw the same objects, whatever their robots do. The one thing a robot
//! changes is *when* an object lands: an object whose place a robot stands on (or is
//! within `clearance` of) waits until the place is clear, its stay counted from when it
//! lands, and so, now and then, whether its zone has room for the next.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use roam_proto::map::GridMeta;
use roam_proto::sim::ObjectTruth;
use roam_world::grid::world_to_cell;
use roam_world::noise;
use roam_world::scenario::changes::ChangeZoneSpec;
use serde::Serialize;

use crate::footprint::Footprint;
use crate::raster::CellXy;

/// Candidate places a zone draws for a new object; the first whose footprint covers no
/// wall and no other object is taken, and none when all are taken.
pub const PLACE_TRIES: usize = 8;

/// A zone where objects appear, in cells.
#[derive(Debug, Clone, PartialEq)]
pub struct ChangeZone {
    pub name: String,
    /// The cells a centre may fall in: x0..=x1, y0..=y1.
    pub x: (i64, i64),
    pub y: (i64, i64),
    pub footprint: Footprint,
    /// The probability of a start per step while the zone has room.
    pub p_start: f64,
    /// The mean stay, steps.
    pub mean_stay_steps: f64,
    pub max_present: u32,
}

impl ChangeZone {
    /// The zone of `spec` on a map `meta`, stepped every `step_s` seconds.
    pub fn new(spec: &ChangeZoneSpec, meta: &GridMeta, step_s: f64) -> ChangeZone {
        let cell = |x: f64, y: f64| {
            world_to_cell(meta, x, y).map_or((0, 0), |(cx, cy)| (cx as i64, cy as i64))
        };
        let [x0, y0, x1, y1] = spec.rect;
        // The rect's far edge is exclusive: its last cell is the one just inside.
        let inside = meta.resolution * 1e-6;
        let (a, b) = (cell(x0, y0), cell(x1 - inside, y1 - inside));
        ChangeZone {
            name: spec.name.clone(),
            x: (a.0, b.0),
            y: (a.1, b.1),
            footprint: Footprint::from_metres(meta, spec.size_m),
            p_start: spec.appear_probability(step_s),
            mean_stay_steps: spec.mean_stay_s / step_s,
            max_present: spec.max_present,
        }
    }
}

/// An object of a zone: placed (or waiting for its place to clear).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SemiStatic {
    /// Unique over the run, in order of start.
    pub id: u64,
    /// The zone's index in the scenario's `changes`.
    pub zone: usize,
    pub centre: CellXy,
    pub footprint: Footprint,
    /// Steps it stays once landed.
    pub stay_steps: u64,
    /// The step it landed on; `None` while a robot stands on its place.
    pub landed_step: Option<u64>,
}

impl SemiStatic {
    /// The step it vanishes on, once landed.
    pub fn leaves_step(&self) -> Option<u64> {
        self.landed_step.map(|s| s + self.stay_steps)
    }

    /// The map cells it covers, inclusive: `[x0, y0, x1, y1]`.
    pub fn cell_bounds(&self) -> [i64; 4] {
        let mut cells = self.footprint.cells(self.centre);
        let first = cells.next().unwrap_or(self.centre);
        let last = cells.last().unwrap_or(first);
        [first.0, first.1, last.0, last.1]
    }
}

/// The objects of `objects` that have landed, as the sim publishes them on
/// `<root>/sim/objects` ([`ObjectTruth`]): what a batch and a live run score against.
pub fn landed_truth(objects: &[SemiStatic]) -> Vec<ObjectTruth> {
    objects
        .iter()
        .filter(|o| o.landed_step.is_some())
        .map(|o| ObjectTruth {
            id: o.id,
            zone: u32::try_from(o.zone).unwrap_or(u32::MAX),
            cells: o.cell_bounds(),
        })
        .collect()
}

/// Every zone's objects and the stream that schedules them.
#[derive(Debug, Clone)]
pub struct Objects {
    zones: Vec<ChangeZone>,
    objects: Vec<SemiStatic>,
    next_id: u64,
    rng: ChaCha8Rng,
}

/// What one step did to the objects: the footprints to cover and to uncover.
#[derive(Debug, Default)]
pub struct ObjectMoves {
    pub landed: Vec<(Footprint, CellXy)>,
    pub left: Vec<(Footprint, CellXy)>,
}

impl Objects {
    pub fn new(zones: Vec<ChangeZone>, seed: u64) -> Objects {
        Objects {
            zones,
            objects: Vec::new(),
            next_id: 0,
            rng: noise::stream(seed, "semi-static"),
        }
    }

    /// Back to no objects, the stream restarted from `seed`.
    pub fn reset(&mut self, seed: u64) {
        self.objects.clear();
        self.next_id = 0;
        self.rng = noise::stream(seed, "semi-static");
    }

    /// The objects now (landed or waiting), oldest first.
    pub fn objects(&self) -> &[SemiStatic] {
        &self.objects
    }

    pub fn zones(&self) -> &[ChangeZone] {
        &self.zones
    }

    /// Step `step`: objects whose stay is over leave, waiting ones land where no robot
    /// stands (`robot_on(footprint, centre)`), and each zone with room may start one on
    /// a place whose cells `free(cell)` allows (no wall) and no other object covers.
    pub fn advance(
        &mut self,
        step: u64,
        free: impl Fn(CellXy) -> bool,
        robot_on: impl Fn(Footprint, CellXy) -> bool,
    ) -> ObjectMoves {
        let mut moves = ObjectMoves::default();
        self.objects.retain(|o| {
            let leaves = o.leaves_step().is_some_and(|s| s <= step);
            if leaves {
                moves.left.push((o.footprint, o.centre));
            }
            !leaves
        });
        for o in &mut self.objects {
            if o.landed_step.is_none() && !robot_on(o.footprint, o.centre) {
                o.landed_step = Some(step);
                moves.landed.push((o.footprint, o.centre));
            }
        }
        for z in 0..self.zones.len() {
            let start = self.rng.random::<f64>() < self.zones[z].p_start;
            if !start {
                continue;
            }
            let zone = &self.zones[z];
            let candidates: Vec<CellXy> = (0..PLACE_TRIES)
                .map(|_| {
                    (
                        self.rng.random_range(zone.x.0..=zone.x.1),
                        self.rng.random_range(zone.y.0..=zone.y.1),
                    )
                })
                .collect();
            let u: f64 = self.rng.random();
            let present = self.objects.iter().filter(|o| o.zone == z).count();
            if present >= zone.max_present as usize {
                continue;
            }
            let footprint = zone.footprint;
            let clear = |c: CellXy| {
                footprint.cells(c).all(|cell| {
                    free(cell)
                        && !self
                            .objects
                            .iter()
                            .any(|o| o.footprint.cells(o.centre).any(|d| d == cell))
                })
            };
            let Some(centre) = candidates.into_iter().find(|&c| clear(c)) else {
                continue;
            };
            // An exponential stay of the zone's mean, at least one step.
            let stay = (-(1.0 - u).ln() * zone.mean_stay_steps).ceil().max(1.0) as u64;
            let landed = !robot_on(footprint, centre);
            if landed {
                moves.landed.push((footprint, centre));
            }
            self.objects.push(SemiStatic {
                id: self.next_id,
                zone: z,
                centre,
                footprint,
                stay_steps: stay,
                landed_step: landed.then_some(step),
            });
            self.next_id += 1;
        }
        moves
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use roam_proto::map::Origin;

    fn meta() -> GridMeta {
        GridMeta {
            width: 40,
            height: 40,
            resolution: 0.25,
            origin: Origin::default(),
        }
    }

    fn zone(per_hour: f64, max_present: u32) -> ChangeZone {
        let spec = ChangeZoneSpec {
            name: "dock".into(),
            rect: [2.0, 2.0, 8.0, 8.0],
            size_m: [1.0, 0.5],
            appear_per_hour: per_hour,
            mean_stay_s: 60.0,
            max_present,
        };
        ChangeZone::new(&spec, &meta(), 1.0)
    }

    fn run(objects: &mut Objects, steps: u64, robot: Option<CellXy>) -> (u64, u64, usize) {
        let (mut landed, mut left, mut most) = (0, 0, 0);
        for step in 1..=steps {
            let moves = objects.advance(
                step,
                |_| true,
                |f, c| robot.is_some_and(|r| f.cells(c).any(|d| d == r)),
            );
            landed += moves.landed.len() as u64;
            left += moves.left.len() as u64;
            most = most.max(objects.objects().len());
        }
        (landed, left, most)
    }

    #[test]
    fn objects_come_at_the_zones_rate_stay_their_mean_and_never_exceed_the_zone() {
        // 360 an hour at 1 s steps, a mean stay of 60 s, room for 4: the zone is
        // mostly full, and every object lands inside its rect.
        let mut objects = Objects::new(vec![zone(360.0, 4)], 7);
        let (landed, left, most) = run(&mut objects, 20_000, None);
        assert!(most <= 4);
        assert!(landed > 200, "{landed}");
        assert!(left + 4 >= landed && left <= landed);
        for o in objects.objects() {
            assert!((8..=31).contains(&o.centre.0) && (8..=31).contains(&o.centre.1));
        }
        // With room for many, starts follow the Poisson rate: 0.1 a step.
        let mut open = Objects::new(vec![zone(360.0, 64)], 7);
        let (landed, _, _) = run(&mut open, 20_000, None);
        let rate = landed as f64 / 20_000.0;
        assert!((rate - 0.1).abs() < 0.01, "{rate}");
        let zero = Objects::new(vec![zone(0.0, 4)], 7);
        assert!(zero.zones()[0].p_start == 0.0);
    }

    #[test]
    fn the_schedule_is_the_seeds_whatever_the_robots_do() {
        let mut alone = Objects::new(vec![zone(360.0, 4)], 3);
        let mut beside = Objects::new(vec![zone(360.0, 4)], 3);
        run(&mut alone, 500, None);
        // A robot standing in the zone delays landings but not the schedule.
        run(&mut beside, 500, Some((20, 20)));
        let ids = |o: &Objects| -> Vec<(u64, CellXy)> {
            o.objects().iter().map(|x| (x.id, x.centre)).collect()
        };
        assert_eq!(ids(&alone)[..1], ids(&beside)[..1]);
        let mut again = Objects::new(vec![zone(360.0, 4)], 3);
        run(&mut again, 500, None);
        assert_eq!(ids(&alone), ids(&again), "same seed, same objects");
    }
}
