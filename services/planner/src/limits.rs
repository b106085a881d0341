//! What one plan may cost, checked before any work: the longest path the budget allows,
//! the memory of a population of such paths, and the GA's total work.
//!
//! - **Path length** (`path_cells`). Paper 000 Eq. 2, `t_ETA = v_lin · Σd + v_ang · Σθ`:
//!   every move covers at least one cell (`resolution` metres) and no turn costs less
//!   than nothing, so a path of L cells takes at least `v_lin · resolution · (L − 1)`
//!   seconds. A path within the budget t_exec therefore has at most
//!   `⌊t_exec / (v_lin · resolution)⌋ + 1` cells, and no chromosome is allowed more:
//!   longer ones could never be on time. roam also caps it at the map's cell count (the
//!   paper's initial walks are at most that long), which bounds it when v_lin = 0.
//! - **Memory** (`max_population_cells`): population × path_cells, the most genes a
//!   generation can hold (4 bytes each, plus the copies selection makes).
//! - **Work** (`max_plan_cost`): population × generations × path_cells, an upper
//!   bound on the cells the GA evaluates, where *generations* are the request's
//!   max_generations or, when fewer, those that can start before its deadline
//!   ([`generations_before_deadline`]): the GA is anytime and stops at its deadline with
//!   its best path so far, so it never does the work it could only do later, and a
//!   request is not refused for it. The generations that fit follow from
//!   [`MAX_CELLS_PER_THREAD_SECOND`], a generous upper bound on the cells one evaluation
//!   thread evaluates in a second, times the deadline and the plan's evaluation threads.
//!   The cells evaluated before the deadline are at most that, and at most population ×
//!   max_generations × path_cells, so the smaller of the two bounds them both.
//!
//! The defaults admit Table I's population (200) and generations (2000) with paths of up
//! to 10,000 cells (a budget just under 1000 s on a 5 cm warehouse map at Table I's
//! 2 s/m; the paper's longest budget, 192 s at 0.2 m, allows 481 cells: 20× less), and
//! population 2000 with paths of 2000 cells. Wall time has its own limit, the CPU budget
//! ([`crate::budget`]).

use crate::params::GaParams;

/// A generous upper bound on the cells one evaluation thread evaluates in a second of
/// CPU, for sizing the work a deadline admits ([`generations_before_deadline`]): 2.5e8.
/// Measured (release, a 2-core machine, Model I, paper 000's workload on 0.2 m cells:
/// population 200, 2000 generations, paths of at most 163 cells, 1.19 s of CPU on two
/// threads) a plan evaluates about 5.5e7 of the limits' cells per CPU-second, counting
/// every chromosome at the longest path the budget allows, so the actual genes are
/// fewer still; 2.5e8 is 4.5 times that, room for a faster core. A debug build is
/// slower, so the bound holds there too. With it, the default `max_plan_cost` of 4e9 is
/// 16 thread-seconds of evaluation: a deadline of 2 s on 4 threads admits any number of
/// generations, and a 600 s deadline (the batch experiments') bounds nothing the cost
/// cap admits.
pub const MAX_CELLS_PER_THREAD_SECOND: f64 = 2.5e8;

/// The limits of one plan; [`crate::PlannerConfig`] sets them per instance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PlanLimits {
    /// Most genes a population may hold: population × path_cells.
    pub max_population_cells: u64,
    /// Most cells a plan may evaluate: population × generations × path_cells, with the
    /// generations that can start before its deadline ([`generations_before_deadline`]).
    pub max_plan_cost: u64,
}

impl Default for PlanLimits {
    fn default() -> Self {
        PlanLimits {
            max_population_cells: 4_000_000,
            max_plan_cost: 4_000_000_000,
        }
    }
}

/// A plan's size, as the limits measure it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PlanSize {
    /// The longest chromosome, cells (see the module doc).
    pub path_cells: usize,
    /// population × path_cells.
    pub population_cells: u64,
    /// The generations the cost counts: max_generations, or the fewer that can start
    /// before the deadline ([`generations_before_deadline`]).
    pub generations: u32,
    /// population × generations × path_cells.
    pub cost: u64,
}

/// A limit a plan exceeds, with what to change.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LimitError {
    #[error("population {population} × {path_cells} cells (the longest path t_exec_s allows, Eq. 2) is {actual} cells, over this planner's max_population_cells of {max}: lower population or t_exec_s")]
    PopulationCells {
        population: usize,
        path_cells: usize,
        actual: u64,
        max: u64,
    },
    #[error("population {population} × {generations} generations{} × {path_cells} cells (the longest path t_exec_s allows, Eq. 2) is a cost of {actual}, over this planner's max_plan_cost of {max}: lower {}population or t_exec_s", cut_note(*.requested, *.generations), if .generations < .requested { "deadline_s, " } else { "max_generations, deadline_s, " })]
    Cost {
        population: usize,
        /// The generations counted: the request's, or those that can start before its
        /// deadline when fewer.
        generations: u32,
        /// The request's max_generations.
        requested: u32,
        path_cells: usize,
        actual: u64,
        max: u64,
    },
    #[error("the seed_route has {actual} points, over the limit of {max} (MAX_SEED_ROUTE_POINTS): send the route left from the start, thinned")]
    SeedRoute { actual: u64, max: u64 },
}

impl LimitError {
    /// The limit's name, as in the config and the error reply.
    pub fn name(&self) -> &'static str {
        match self {
            LimitError::PopulationCells { .. } => "max_population_cells",
            LimitError::Cost { .. } => "max_plan_cost",
            LimitError::SeedRoute { .. } => "max_seed_route_points",
        }
    }

    /// The limit and the value the request had.
    pub fn max_actual(&self) -> (u64, u64) {
        match *self {
            LimitError::PopulationCells { max, actual, .. }
            | LimitError::Cost { max, actual, .. }
            | LimitError::SeedRoute { max, actual } => (max, actual),
        }
    }
}

/// The most cells a path within `t_exec_s` can have (Eq. 2, see the module doc), at
/// most `map_cells`.
pub fn path_cells(resolution: f64, v_lin: f64, t_exec_s: f64, map_cells: usize) -> usize {
    let per_cell = v_lin * resolution;
    if per_cell.is_nan() || per_cell <= 0.0 || !t_exec_s.is_finite() {
        return map_cells;
    }
    // The relative slack keeps a path whose summed ETA equals t_exec up to rounding.
    let moves = (t_exec_s / per_cell * (1.0 + 1e-12)).floor();
    if moves >= map_cells as f64 {
        map_cells
    } else {
        (moves.max(0.0) as usize + 1).min(map_cells)
    }
}

/// What [`LimitError::Cost`] says of generations cut at the deadline.
fn cut_note(requested: u32, generations: u32) -> String {
    if generations < requested {
        format!(
            " (of the {requested} max_generations asked for, the most that can start within deadline_s at up to {MAX_CELLS_PER_THREAD_SECOND:.1e} cells per thread-second)"
        )
    } else {
        String::new()
    }
}

/// The most generations of `population` chromosomes of at most `path_cells` cells that
/// can start within `thread_seconds` (the deadline times the evaluation threads) at
/// [`MAX_CELLS_PER_THREAD_SECOND`]: those that fit, and the one in progress when the
/// deadline comes. At least 1; `u64::MAX` for an unbounded (infinite) time.
pub fn generations_before_deadline(
    thread_seconds: f64,
    population: usize,
    path_cells: usize,
) -> u64 {
    let per_generation = (population as f64 * path_cells as f64).max(1.0);
    let fit = (thread_seconds.max(0.0) * MAX_CELLS_PER_THREAD_SECOND / per_generation).floor();
    if fit.is_nan() || fit >= u64::MAX as f64 {
        u64::MAX
    } else {
        fit as u64 + 1
    }
}

/// Sizes a GA plan that may evaluate for `thread_seconds` (its deadline times its
/// evaluation threads; infinite for no deadline) and checks it against `limits`.
pub fn check(
    params: &GaParams,
    resolution: f64,
    t_exec_s: f64,
    map_cells: usize,
    thread_seconds: f64,
    limits: &PlanLimits,
) -> Result<PlanSize, LimitError> {
    let path_cells = path_cells(resolution, params.v_lin, t_exec_s, map_cells);
    let saturate = |v: u128| u64::try_from(v).unwrap_or(u64::MAX);
    let population_cells = saturate(params.population as u128 * path_cells as u128);
    let fit = generations_before_deadline(thread_seconds, params.population, path_cells);
    // Fewer than u32::MAX, since max_generations is a u32.
    let generations = u64::from(params.max_generations).min(fit) as u32;
    let cost = saturate(params.population as u128 * u128::from(generations) * path_cells as u128);
    if population_cells > limits.max_population_cells {
        return Err(LimitError::PopulationCells {
            population: params.population,
            path_cells,
            actual: population_cells,
            max: limits.max_population_cells,
        });
    }
    if cost > limits.max_plan_cost {
        return Err(LimitError::Cost {
            population: params.population,
            generations,
            requested: params.max_generations,
            path_cells,
            actual: cost,
            max: limits.max_plan_cost,
        });
    }
    Ok(PlanSize {
        path_cells,
        population_cells,
        generations,
        cost,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_path_bound_is_the_budget_at_the_robots_speed() {
        // Table I: 2 s/m; 0.2 m cells: 0.4 s per cell; 80 s: 200 moves, 201 cells.
        assert_eq!(path_cells(0.2, 2.0, 80.0, 10_000), 201);
        assert_eq!(path_cells(0.2, 2.0, 80.1, 10_000), 201);
        assert_eq!(path_cells(0.2, 2.0, 0.39, 10_000), 1);
        // Capped by the map; v_lin = 0 makes moves free, so only the map bounds it.
        assert_eq!(path_cells(0.05, 2.0, 86_400.0, 1 << 20), 864_001);
        assert_eq!(path_cells(0.05, 2.0, 86_400.0, 100_000), 100_000);
        assert_eq!(path_cells(0.2, 0.0, 80.0, 10_000), 10_000);
        assert_eq!(path_cells(0.2, 1e-300, 80.0, 10_000), 10_000);
    }

    #[test]
    fn a_path_on_budget_is_never_longer_than_the_bound() {
        // k straight moves cost k · v_lin · resolution as Eq. 2 sums them; with a budget
        // of exactly that the bound still admits the path.
        for k in [1usize, 7, 200, 9_999] {
            let eta: f64 = (0..k).map(|_| 2.0 * 0.2).sum();
            // k moves are k + 1 cells.
            assert!(path_cells(0.2, 2.0, eta, usize::MAX) > k, "k = {k}");
        }
    }

    #[test]
    fn the_papers_workload_fits_and_the_attack_does_not() {
        let limits = PlanLimits::default();
        let table_one = GaParams::default();
        // The paper's longest budget (0.8 × 240 s) at its 0.2 m cells: 481 cells.
        let size = check(&table_one, 0.2, 192.0, 1_700_000, f64::INFINITY, &limits).expect("fits");
        assert_eq!(size.path_cells, 481);
        assert_eq!(size.cost, 200 * 2000 * 481);
        // A 1000 s budget on a 1.7 M-cell warehouse at 5 cm: 10,001 cells, just over
        // the cost cap; 999 s fits.
        assert!(check(&table_one, 0.05, 999.0, 1_700_000, f64::INFINITY, &limits).is_ok());
        // The attack: population 2000, 100,000 generations, a day's budget, 1024² at 5 cm.
        let attack = GaParams {
            population: 2000,
            max_generations: 100_000,
            ..GaParams::default()
        };
        let err =
            check(&attack, 0.05, 86_400.0, 1 << 20, f64::INFINITY, &limits).expect_err("refused");
        assert_eq!(err.name(), "max_population_cells");
        assert_eq!(err.max_actual(), (4_000_000, 2000 * 864_001));
        assert!(
            err.to_string().contains("lower population or t_exec_s"),
            "{err}"
        );
        // Within memory but not within the cost cap.
        let long = GaParams {
            population: 2000,
            max_generations: 100_000,
            ..GaParams::default()
        };
        let err = check(&long, 0.2, 80.0, 10_000, f64::INFINITY, &limits).expect_err("refused");
        assert_eq!(err.name(), "max_plan_cost");
        assert_eq!(err.max_actual().1, 2000 * 100_000 * 201);
        assert!(err.to_string().contains("lower max_generations"), "{err}");
    }

    #[test]
    fn a_deadline_bounds_the_generations_the_cost_counts() {
        let limits = PlanLimits::default();
        // Model I at Table I's population, 100,000 generations, an 80 s budget on 0.2 m
        // cells (201 cells): 4.02e9, over the cap without a deadline.
        let curious = GaParams {
            max_generations: 100_000,
            ..GaParams::default()
        };
        let err = check(&curious, 0.2, 80.0, 10_000, f64::INFINITY, &limits).expect_err("over");
        assert_eq!(err.max_actual(), (4_000_000_000, 200 * 100_000 * 201));
        // With a 2 s deadline on 4 threads: 8 thread-seconds at 2.5e8 cells each is 2e9
        // cells, 49,751 generations of 200 × 201 and the one in progress.
        assert_eq!(generations_before_deadline(8.0, 200, 201), 49_752);
        let size = check(&curious, 0.2, 80.0, 10_000, 2.0 * 4.0, &limits).expect("admitted");
        assert_eq!(size.generations, 49_752);
        assert_eq!(size.cost, 200 * 49_752 * 201);
        assert!(size.cost <= limits.max_plan_cost);
        // A deadline that fits all the generations counts them all: 20 s on 4 threads.
        let err = check(&curious, 0.2, 80.0, 10_000, 20.0 * 4.0, &limits).expect_err("over");
        assert_eq!(err.name(), "max_plan_cost");
        assert_eq!(err.max_actual().1, 200 * 100_000 * 201);
        assert!(
            err.to_string()
                .contains("lower max_generations, deadline_s"),
            "{err}"
        );
        // Population 2000 in 10 s on 4 threads: 24,876 of its 100,000 generations can
        // start, still 1e10 cells; refused with the cut named.
        let wide = GaParams {
            population: 2000,
            ..curious.clone()
        };
        let err = check(&wide, 0.2, 80.0, 10_000, 10.0 * 4.0, &limits).expect_err("over");
        assert_eq!(err.name(), "max_plan_cost");
        assert_eq!(err.max_actual().1, 2000 * 24_876 * 201);
        let message = err.to_string();
        assert!(
            message.contains("24876 generations (of the 100000 max_generations asked for")
                && message.contains("lower deadline_s, population or t_exec_s"),
            "{message}"
        );
        // Memory is not the deadline's: population × path_cells stays as it is.
        let huge = GaParams {
            population: 20_000,
            ..curious
        };
        let err = check(&huge, 0.2, 80.0, 10_000, 0.01, &limits).expect_err("memory");
        assert_eq!(err.name(), "max_population_cells");
        // Degenerate times: none counts one generation, infinity counts them all.
        assert_eq!(generations_before_deadline(0.0, 200, 201), 1);
        assert_eq!(
            generations_before_deadline(f64::INFINITY, 200, 201),
            u64::MAX
        );
        assert_eq!(generations_before_deadline(1.0, 0, 0), 250_000_001);
    }

    #[test]
    fn sizes_saturate_instead_of_overflowing() {
        let limits = PlanLimits {
            max_population_cells: u64::MAX,
            max_plan_cost: u64::MAX,
        };
        let huge = GaParams {
            population: usize::MAX / 2,
            max_generations: u32::MAX,
            ..GaParams::default()
        };
        let size = check(&huge, 0.2, 80.0, usize::MAX, f64::INFINITY, &limits).expect("no limit");
        assert_eq!(size.cost, u64::MAX);
    }
}
