//! What roam's seeding buys: each configuration planned with roam's initialization and
//! with paper 000's own (§II.A.1, random walks only) on the same seeds, side by side.
//!
//! Under roam's initialization "within budget" and "reached goal" are forced: the
//! shortest path (checked to fit t_exec) is in every first population, elitism keeps
//! the best chromosome, every random walk is finished at G, and W_2 + W_3 (Eqs. 4–5,
//! 1,500,000 at Table I) outweigh any F1 a path can reach, so the GA can never prefer a
//! path that is late or misses G. Under the paper's they are findings.

use serde::Serialize;

use super::row::Row;

/// One configuration under both initializations.
#[derive(Debug, Clone, Serialize)]
pub struct SeedingRow {
    pub goal: String,
    pub ratio: String,
    pub model: String,
    pub roam: Figures,
    pub paper: Figures,
}

/// The figures compared: budget adherence and information.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Figures {
    /// Share of runs whose t_ETA fits t_exec (forced to 1 under roam's seeding).
    pub within_budget: f64,
    /// Share of runs whose path ends at G (forced to 1 under roam's seeding).
    pub reached_goal: f64,
    pub distinct_information_median: f64,
    pub u_ges_median: f64,
}

impl From<&Row> for Figures {
    fn from(r: &Row) -> Self {
        Figures {
            within_budget: r.within_budget,
            reached_goal: r.reached_goal,
            distinct_information_median: r.distinct_information_median,
            u_ges_median: r.u_ges_median,
        }
    }
}

/// Pairs the rows of the two runs by configuration (rows only one run has are left out).
pub fn side_by_side(roam: &[Row], paper: &[Row]) -> Vec<SeedingRow> {
    roam.iter()
        .filter_map(|r| {
            let p = paper
                .iter()
                .find(|p| p.goal == r.goal && p.ratio == r.ratio && p.model == r.model)?;
            Some(SeedingRow {
                goal: r.goal.clone(),
                ratio: r.ratio.clone(),
                model: r.model.clone(),
                roam: r.into(),
                paper: p.into(),
            })
        })
        .collect()
}

/// The side-by-side table as text.
pub struct Table<'a>(pub &'a [SeedingRow]);

impl std::fmt::Display for Table<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "what roam's seeding buys: roam's initialization | paper 000's (random walks only), same seeds;"
        )?;
        writeln!(
            f,
            "under roam's, budget and goal are forced to 100% by the shortest-path seed"
        )?;
        writeln!(
            f,
            "{:<6} {:<6} {:<7} | {:>7} {:>7} {:>7} {:>8} | {:>7} {:>7} {:>7} {:>8}",
            "goal",
            "ratio",
            "model",
            "budget",
            "goal",
            "I seen",
            "U med",
            "budget",
            "goal",
            "I seen",
            "U med"
        )?;
        for r in self.0 {
            writeln!(
                f,
                "{:<6} {:<6} {:<7} | {:>6.0}% {:>6.0}% {:>7.0} {:>8.0} | {:>6.0}% {:>6.0}% {:>7.0} {:>8.0}",
                r.goal,
                r.ratio,
                r.model,
                r.roam.within_budget * 100.0,
                r.roam.reached_goal * 100.0,
                r.roam.distinct_information_median,
                r.roam.u_ges_median,
                r.paper.within_budget * 100.0,
                r.paper.reached_goal * 100.0,
                r.paper.distinct_information_median,
                r.paper.u_ges_median,
            )?;
        }
        Ok(())
    }
}
