//! The GA's parameters: paper 000 Table I's values are the defaults, and every one can
//! be overridden per request. Ranges are checked, and an out-of-range value is refused
//! with its name and range.

use roam_proto::planner::GaOverrides;

/// The parameters of one plan.
#[derive(Debug, Clone, PartialEq)]
pub struct GaParams {
    /// N_p: chromosomes per population (Table I: 200).
    pub population: usize,
    /// N: maximum generations (Table I: 2000).
    pub max_generations: u32,
    /// r_c: share of chromosomes crossed per generation (Table I: 0.7).
    pub crossover_ratio: f64,
    /// r_m: share of chromosomes mutated per generation (Table I: 0.3).
    pub mutation_ratio: f64,
    /// p_m: share of genes mutated in a mutated chromosome (Table I: 0.1).
    pub mutation_percentage: f64,
    /// v_lin (Table I: 2.0). Ambiguity: Table I calls it a velocity in m/s, but Eq. 2
    /// multiplies it by distance, so it acts as seconds per metre. roam follows Eq. 2:
    /// 2.0 s/m, i.e. a robot averaging 0.5 m/s.
    pub v_lin: f64,
    /// v_ang (Table I: 1.0), seconds per radian of turning, by the same reading of Eq. 2.
    pub v_ang: f64,
    /// W_1: weight of the curiosity model's information (Table I: 3).
    pub w1: f64,
    /// W_2: reward when t_ETA < t_exec (Table I: 500000).
    pub w2: f64,
    /// W_3: reward when the last gene is the goal (Table I: 1000000).
    pub w3: f64,
    /// W_4: penalty per second of overtime. Table I lists -200 while Eq. 6 already
    /// subtracts it; roam stores the magnitude (200) and subtracts, as Eq. 6 does.
    pub w4: f64,
    /// W_5: penalty per second of unused time, magnitude (Table I: -10; see `w4`).
    pub w5: f64,
    /// w_t: Model I decay for the time between similar stimuli (Table I: 0.4).
    pub w_t: f64,
    /// w_n: Model I decay for the number of similar stimuli (Table I: 0.01).
    pub w_n: f64,
    /// c_h: heuristic compression for Model II (Table I: 0.25).
    pub heuristic_compression: f64,
    /// d: perception diameter in cells (paper 000 §III: 3). Eq. 3 sums x and y from
    /// [-d/2] to [d/2]; roam reads the brackets as floor, which gives -2..=1 for d = 3:
    /// the paper's "16-cell neighbourhood" (4 × 4, one cell wider behind than ahead).
    pub perception_diameter: u32,
    /// I_0: Model 0's gain per newly perceived cell (Eq. 8). Not in Table I; 1.0 here.
    pub coverage_gain: f64,
    /// W_loc: roam's coupling of paper 002 into paper 000's fitness. When the planner
    /// has a PEB layer (localization's `peb`), the fitness subtracts W_loc · Σ PEB (m)
    /// over the path's genes, so a path through corridors where the controller would
    /// have to fight for its position costs more. 0 (off) by default: Table I has no
    /// such term.
    pub w_loc: f64,
    /// The PEB the localizability cost forgives, metres: each gene costs
    /// W_loc · max(0, PEB − `peb_free_m`). 0 (every decimetre costs) by default, the
    /// rule the single-robot day was measured with. Where anchors cover the floor the
    /// PEB is a few decimetres everywhere, so with 0 the cost is mostly a tax on length,
    /// which a fleet planning on news (little information a metre) cannot pay: a
    /// threshold below the controller's hold (`max_peb_m`, 2 m) keeps the cost where
    /// the anchor gaps are (`roam reproduce fleet` uses 0.5 m; its README).
    pub peb_free_m: f64,
    /// Share of the first population built through via-points ([`crate::seeds`]): paths
    /// S → v₁ → … → G through cells drawn from the information layer, joined by shortest
    /// paths and kept only within the budget (Eq. 2). roam's, not paper 000's, whose
    /// first population is random walks only (§II.A.1): random walks from S seldom find
    /// information off the straight route. 0 (with `walk_end_share` 0) is the paper's
    /// initialization ([`GaParams::with_paper_initialization`]). Default 0.25.
    pub via_share: f64,
    /// The share of t_exec a random walk must have used (Eq. 2) before it may end: a
    /// walk that arrives at G earlier passes through it, one that reaches its drawn
    /// length earlier walks on; then it is finished at G. roam's round-trip rule
    /// ([`crate::ga`]): the paper's walks stop at G at once, so with start = goal every
    /// walk was the one cell S and the robot was told to stand still. 0 is the paper's
    /// rule. Default 0.5.
    pub walk_end_share: f64,
    /// Paper 000 §II.A.1 to the letter: the first population is random walks only,
    /// each of a length drawn between the Manhattan distance and the map's cell count
    /// (cut at the chromosome bound, [`crate::ga::GaOptions::max_path_cells`]) and
    /// stopping there or at G; no shortest path, no via-point seeds, walks not finished
    /// at G, and the plan is the GA's best even where the shortest path is fitter
    /// ([`crate::best`] is skipped). roam's seeding guarantees that a plan reaches the
    /// goal on time; this switch shows what the paper's own start gives without that
    /// guarantee (`roam reproduce planner` runs both). Not a request field: a service
    /// that can return a path that misses the goal is a reproduction, not a planner.
    /// Default false. See [`GaParams::with_random_walks_only`].
    pub random_walks_only: bool,
}

impl Default for GaParams {
    fn default() -> Self {
        GaParams {
            population: 200,
            max_generations: 2000,
            crossover_ratio: 0.7,
            mutation_ratio: 0.3,
            mutation_percentage: 0.1,
            v_lin: 2.0,
            v_ang: 1.0,
            w1: 3.0,
            w2: 500_000.0,
            w3: 1_000_000.0,
            w4: 200.0,
            w5: 10.0,
            w_t: 0.4,
            w_n: 0.01,
            heuristic_compression: 0.25,
            perception_diameter: 3,
            coverage_gain: 1.0,
            w_loc: 0.0,
            peb_free_m: 0.0,
            via_share: DEFAULT_VIA_SHARE,
            walk_end_share: DEFAULT_WALK_END_SHARE,
            random_walks_only: false,
        }
    }
}

/// Default [`GaParams::via_share`].
pub const DEFAULT_VIA_SHARE: f64 = 0.25;
/// Default [`GaParams::walk_end_share`].
pub const DEFAULT_WALK_END_SHARE: f64 = 0.5;

/// The largest population a request may ask for.
pub const MAX_POPULATION: usize = 2000;
/// The most generations a request may ask for.
pub const MAX_GENERATIONS: u32 = 100_000;
/// The widest perception diameter, in cells.
pub const MAX_PERCEPTION_DIAMETER: u32 = 15;

use roam_world::param::check_param as check;
pub use roam_world::param::ParamError;

impl GaParams {
    /// Table I's values with the request's overrides applied, then checked.
    pub fn with_overrides(overrides: &GaOverrides) -> Result<GaParams, ParamError> {
        let mut p = GaParams::default();
        let o = overrides;
        if let Some(v) = o.population {
            p.population = v as usize;
        }
        if let Some(v) = o.max_generations {
            p.max_generations = v;
        }
        macro_rules! take {
            ($($field:ident),*) => { $( if let Some(v) = o.$field { p.$field = v; } )* };
        }
        take!(
            crossover_ratio,
            mutation_ratio,
            mutation_percentage,
            v_lin,
            v_ang,
            w1,
            w2,
            w3,
            w4,
            w5,
            w_t,
            w_n,
            heuristic_compression,
            coverage_gain,
            w_loc,
            peb_free_m,
            via_share,
            walk_end_share
        );
        if let Some(v) = o.perception_diameter {
            p.perception_diameter = v;
        }
        p.validate()?;
        Ok(p)
    }

    /// Checks every parameter's range.
    pub fn validate(&self) -> Result<(), ParamError> {
        let pop = self.population as f64;
        check(
            "population",
            pop,
            (2..=MAX_POPULATION).contains(&self.population),
            "2..=2000",
        )?;
        check(
            "max_generations",
            f64::from(self.max_generations),
            (1..=MAX_GENERATIONS).contains(&self.max_generations),
            "1..=100000",
        )?;
        for (name, v) in [
            ("crossover_ratio", self.crossover_ratio),
            ("mutation_ratio", self.mutation_ratio),
            ("mutation_percentage", self.mutation_percentage),
            ("via_share", self.via_share),
            ("walk_end_share", self.walk_end_share),
        ] {
            check(name, v, (0.0..=1.0).contains(&v), "0..=1")?;
        }
        // v_lin 0 would be a robot that drives any distance in no time: every path
        // fits every budget and the budget's cell bound (limits.rs) is the whole map.
        // Turning may be free (a point robot), driving may not.
        check(
            "v_lin",
            self.v_lin,
            self.v_lin > 0.0 && self.v_lin <= 1000.0,
            "(0, 1000] seconds per metre",
        )?;
        check(
            "v_ang",
            self.v_ang,
            (0.0..=1000.0).contains(&self.v_ang),
            "0..=1000 seconds per radian",
        )?;
        for (name, v) in [
            ("w1", self.w1),
            ("w2", self.w2),
            ("w3", self.w3),
            ("w4", self.w4),
            ("w5", self.w5),
            ("w_t", self.w_t),
            ("w_n", self.w_n),
            ("coverage_gain", self.coverage_gain),
            ("w_loc", self.w_loc),
        ] {
            check(
                name,
                v,
                (0.0..=1e12).contains(&v),
                "a magnitude in 0..=1e12 (penalties are subtracted)",
            )?;
        }
        check(
            "peb_free_m",
            self.peb_free_m,
            (0.0..=1000.0).contains(&self.peb_free_m),
            "0..=1000 metres",
        )?;
        check(
            "heuristic_compression",
            self.heuristic_compression,
            self.heuristic_compression > 0.0 && self.heuristic_compression <= 1.0,
            "(0, 1]",
        )?;
        check(
            "perception_diameter",
            f64::from(self.perception_diameter),
            (1..=MAX_PERCEPTION_DIAMETER).contains(&self.perception_diameter),
            "1..=15 cells",
        )?;
        Ok(())
    }

    /// These parameters with paper 000's own initialization (§II.A.1): no via-point
    /// seeds and walks that stop at G at once. What roam added before this issue stays
    /// (walks capped by the budget and finished at G, the shortest path in the first
    /// population), so plans made this way are the plans roam made before via-points
    /// and round trips, bit for bit.
    pub fn with_paper_initialization(self) -> GaParams {
        GaParams {
            via_share: 0.0,
            walk_end_share: 0.0,
            ..self
        }
    }

    /// These parameters with paper 000's initialization to the letter (see
    /// [`GaParams::random_walks_only`]): [`GaParams::with_paper_initialization`]
    /// without the shortest path, without finishing walks at G, and without the
    /// fallback to the shortest path after the GA.
    pub fn with_random_walks_only(self) -> GaParams {
        GaParams {
            random_walks_only: true,
            ..self.with_paper_initialization()
        }
    }

    /// Whether the first population is paper 000's (see
    /// [`GaParams::with_paper_initialization`]).
    pub fn is_paper_initialization(&self) -> bool {
        self.via_share == 0.0 && self.walk_end_share == 0.0
    }

    /// The perception window's offsets, Eq. 3 with floor brackets (see
    /// [`GaParams::perception_diameter`]).
    pub fn window(&self) -> Vec<(i32, i32)> {
        let d = self.perception_diameter as i32;
        let lo = (-d).div_euclid(2);
        let hi = d.div_euclid(2);
        let mut offsets = Vec::new();
        for y in lo..=hi {
            for x in lo..=hi {
                offsets.push((x, y));
            }
        }
        offsets
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_one_is_the_default_and_d3_sees_16_cells() {
        let p = GaParams::default();
        assert_eq!((p.population, p.max_generations), (200, 2000));
        assert_eq!(p.window().len(), 16);
        assert!(p.validate().is_ok());
    }

    #[test]
    fn overrides_apply_and_ranges_are_named() {
        let p = GaParams::with_overrides(&GaOverrides {
            population: Some(50),
            w1: Some(5.0),
            ..GaOverrides::default()
        })
        .expect("valid");
        assert_eq!((p.population, p.w1), (50, 5.0));
        let err = GaParams::with_overrides(&GaOverrides {
            crossover_ratio: Some(1.5),
            ..GaOverrides::default()
        })
        .expect_err("must be refused");
        assert_eq!(err.name, "crossover_ratio");
        assert!(err.to_string().contains("0..=1"));
        for (name, overrides) in [
            (
                "via_share",
                GaOverrides {
                    via_share: Some(-0.1),
                    ..GaOverrides::default()
                },
            ),
            (
                "walk_end_share",
                GaOverrides {
                    walk_end_share: Some(1.5),
                    ..GaOverrides::default()
                },
            ),
        ] {
            let err = GaParams::with_overrides(&overrides).expect_err("must be refused");
            assert_eq!(err.name, name);
        }
    }

    #[test]
    fn an_impossible_time_model_is_refused_and_free_turning_is_not() {
        for v_lin in [0.0, -1.0, f64::NAN, f64::INFINITY, 1001.0] {
            let err = GaParams::with_overrides(&GaOverrides {
                v_lin: Some(v_lin),
                ..GaOverrides::default()
            })
            .expect_err("a robot that drives in no time (or backwards) is no time model");
            assert_eq!(err.name, "v_lin");
            assert!(err.to_string().contains("(0, 1000]"), "{err}");
        }
        let err = GaParams::with_overrides(&GaOverrides {
            v_ang: Some(-0.5),
            ..GaOverrides::default()
        })
        .expect_err("negative turning time");
        assert_eq!(err.name, "v_ang");
        // A point robot turns for free.
        let p = GaParams::with_overrides(&GaOverrides {
            v_ang: Some(0.0),
            v_lin: Some(0.9),
            ..GaOverrides::default()
        })
        .expect("v_ang 0 is a point robot");
        assert_eq!((p.v_lin, p.v_ang), (0.9, 0.0));
    }

    #[test]
    fn the_papers_initialization_is_one_call_away() {
        let roam = GaParams::default();
        assert!(!roam.is_paper_initialization());
        let paper = roam.clone().with_paper_initialization();
        assert!(paper.is_paper_initialization());
        assert_eq!((paper.via_share, paper.walk_end_share), (0.0, 0.0));
        // Nothing else changes.
        assert_eq!(
            GaParams {
                via_share: roam.via_share,
                walk_end_share: roam.walk_end_share,
                ..paper
            },
            roam
        );
        let strict = roam.clone().with_random_walks_only();
        assert!(strict.is_paper_initialization() && strict.random_walks_only);
        assert!(
            !paper.random_walks_only,
            "the shortest path stays by default"
        );
    }
}
