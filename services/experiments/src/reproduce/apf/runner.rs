//! `roam reproduce apf`: paper 002 §4's ES1–ES3 on the shipped scenarios (built into the
//! binary, so it runs from anywhere), with progress reported to the caller, the pictures, and the
//! paper's claims judged from the figures ([`claims`]).

use std::path::{Path, PathBuf};

use crate::closed_loop::setup::Setup;
use crate::reproduce::apf::{paper, reproduce, ReproduceOptions, Reproduction};
use roam_world::scenario::{self, Scenario};
use roam_world::DEFAULT_MAX_CELLS;
use serde::Serialize;

use crate::progress::Progress;
use crate::verdict::Comparison;
use crate::ExperimentError;

const ES1: &str = include_str!("../../../../../config/scenarios/es1.yaml");
const ES2: &str = include_str!("../../../../../config/scenarios/es2.yaml");
const ES3: &str = include_str!("../../../../../config/scenarios/es3.yaml");

/// How much to run.
#[derive(Debug, Clone)]
pub struct Sizes {
    pub es1_runs: usize,
    pub es2_runs: usize,
    pub es3_missions: usize,
    pub es3_runs: usize,
    pub seed: u64,
    pub out_dir: PathBuf,
}

fn shipped(name: &str, text: &str) -> Result<Scenario, ExperimentError> {
    Ok(scenario::parse(Path::new(name), text, DEFAULT_MAX_CELLS)?)
}

/// What `roam reproduce apf` prints: the reproduction (its keys at the top level of the
/// JSON: `es1`, `es1_no_guard`, `es2`, `es3`) and the paper's claims with their verdicts.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Output {
    #[serde(flatten)]
    pub reproduction: Reproduction,
    pub claims: Vec<Comparison>,
}

impl Output {
    /// The claims judged from `reproduction`'s figures.
    pub fn of(reproduction: Reproduction) -> Output {
        let claims = super::claims::compare(&reproduction);
        Output {
            reproduction,
            claims,
        }
    }

    /// The comparison table, then the claims, for the terminal.
    pub fn text(&self) -> String {
        format!(
            "{}\npaper 002's claims, judged from our figures:\n{}",
            paper::comparison_table(&self.reproduction),
            crate::verdict::lines(&self.claims)
        )
    }
}

/// Runs the three experiments with the paper's parameters, writes the pictures and
/// judges the claims; `progress` after each run, one stage per experiment.
pub fn run(
    sizes: &Sizes,
    progress: Progress<'_>,
) -> Result<(Output, Vec<PathBuf>), ExperimentError> {
    let es1 = shipped("es1.yaml", ES1)?;
    let es2 = shipped("es2.yaml", ES2)?;
    let es3 = shipped("es3.yaml", ES3)?;
    let params = paper::paper_params();
    let options = ReproduceOptions {
        es1_runs: sizes.es1_runs,
        es2_runs: sizes.es2_runs,
        es3_missions: sizes.es3_missions,
        es3_runs: sizes.es3_runs,
        seed: sizes.seed,
        threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
        params: &params,
        progress,
    };
    let result = reproduce(&es1, &es2, &es3, &options)?;
    std::fs::create_dir_all(&sizes.out_dir).map_err(|e| {
        ExperimentError::Setup(format!("cannot create {}: {e}", sizes.out_dir.display()))
    })?;
    let pictures = crate::reproduce::apf::render::write_figures(
        &result,
        &Setup::new(&es1)?,
        &Setup::new(&es2)?,
        &sizes.out_dir,
        sizes.seed,
    )?;
    Ok((Output::of(result), pictures))
}
