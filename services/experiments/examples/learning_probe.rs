//! Why does the learner not beat the uniform mix on grid004? Measurements behind the
//! README's "learning against the uniform mix" (issue 18), from the runs' insides via
//! [`experiment::trace`]:
//!
//! 1. per episode of the uniform mix (strategies assigned at random, so a controlled
//!    comparison): the reward R and the fall of the rate error during the episode, by
//!    strategy, overall and by the (p, r) at the choice;
//! 2. in curious mode: P(recency) at each choice, and how far V_recency and V_poisson
//!    are apart there;
//! 3. the feature r against time in one run, and the cells never seen;
//! 4. with `--sweep`: curious's AUC against uniform's for a range of τ, episode and
//!    feature variants, `REPS` repetitions each, also paired by repetition (the modes
//!    share their random numbers).
//!
//! `cargo run --release -p roam-mapper --example learning_probe [-- --sweep]`

use roam_experiments::reproduce::mapper::experiment::{self, ExperimentOptions};
use roam_experiments::reproduce::mapper::truth::true_rates;
use roam_mapper::explorer::AfterRandomStep;
use roam_mapper::learner::{Mode, Strategy};

const REPS: usize = 20;

#[derive(Default, Clone, Copy)]
struct Stat {
    n: f64,
    sum: f64,
    sq: f64,
}

impl Stat {
    fn add(&mut self, v: f64) {
        self.n += 1.0;
        self.sum += v;
        self.sq += v * v;
    }
    fn mean(&self) -> f64 {
        self.sum / self.n.max(1.0)
    }
    /// Standard error of the mean.
    fn se(&self) -> f64 {
        let m = self.mean();
        ((self.sq / self.n.max(1.0) - m * m).max(0.0) / self.n.max(1.0)).sqrt()
    }
    fn show(&self) -> String {
        format!("{:.4} ± {:.4} (n {})", self.mean(), self.se(), self.n)
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let scenario = experiment::grid004()?;
    let truth = true_rates(&scenario, scenario.file.time.step_s)?;
    let options = ExperimentOptions {
        repetitions: REPS,
        ..ExperimentOptions::default()
    };
    // 1. The uniform mix: reward and error fall per episode, by strategy and region.
    let p_bins = [0.0, 2.0, 5.0, 10.0, 20.0, f64::INFINITY];
    let r_bins = [0.0, 200.0, 500.0, 1000.0, f64::INFINITY];
    let bin = |v: f64, edges: &[f64]| edges.windows(2).position(|w| v < w[1]).unwrap_or(0);
    let mut reward = [Stat::default(); 2];
    let mut fall = [Stat::default(); 2];
    let mut by_region = vec![[Stat::default(); 2]; (p_bins.len() - 1) * (r_bins.len() - 1)];
    let mut by_region_fall = by_region.clone();
    for rep in 0..REPS {
        // (strategy, bin, error at the start) of the running episode.
        let mut running: Option<(usize, usize, f64)> = None;
        experiment::trace(&scenario, &options, Mode::Uniform, rep, &mut |v| {
            let error = experiment::rate_error_of(v.map, &truth);
            if let Some(end) = v.next.episode {
                if let Some((s, b, e0)) = running {
                    reward[s].add(end.reward);
                    fall[s].add(e0 - error);
                    by_region[b][s].add(end.reward);
                    by_region_fall[b][s].add(e0 - error);
                }
            }
            if v.next.episode.is_some() || running.is_none() {
                let f = v.next.features;
                let b = bin(f.p, &p_bins) * (r_bins.len() - 1) + bin(f.r, &r_bins);
                let s = usize::from(v.next.strategy == Strategy::Poisson);
                running = Some((s, b, error));
            }
        })?;
    }
    println!("uniform mix, {REPS} runs: per episode, by the strategy drawn");
    for (s, name) in ["recency", "poisson"].iter().enumerate() {
        println!(
            "  {name:<8} reward {}  error fall {:.2e} ± {:.1e}",
            reward[s].show(),
            fall[s].mean(),
            fall[s].se()
        );
    }
    println!("  by (p, r) at the choice: reward recency | poisson; error fall recency | poisson");
    for (i, cell) in by_region.iter().enumerate() {
        if cell[0].n + cell[1].n < 20.0 {
            continue;
        }
        let (pi, ri) = (i / (r_bins.len() - 1), i % (r_bins.len() - 1));
        let f = &by_region_fall[i];
        println!(
            "  p {:>4}-{:<4} r {:>4}-{:<4}: {} | {};  {:+.1e} | {:+.1e}",
            p_bins[pi],
            p_bins[pi + 1],
            r_bins[ri],
            r_bins[ri + 1],
            cell[0].show(),
            cell[1].show(),
            f[0].mean(),
            f[1].mean()
        );
    }
    // 2. Curious: how far the softmax is from 1/2 and the values from each other.
    let mut p_rec = Stat::default();
    let mut dist = Stat::default();
    let mut gap = Stat::default();
    let mut both = 0u64;
    let mut choices = 0u64;
    let mut beyond = [0u64; 3];
    for rep in 0..REPS {
        experiment::trace(&scenario, &options, Mode::Curious, rep, &mut |v| {
            if v.next.episode.is_none() {
                return;
            }
            let f = v.next.features;
            let l = v.explorer.learner();
            let p = l.probabilities(f)[0];
            let (a, b) = (l.value(Strategy::Recency, f), l.value(Strategy::Poisson, f));
            choices += 1;
            p_rec.add(p);
            dist.add((p - 0.5).abs());
            if a != 0.0 && b != 0.0 {
                both += 1;
                gap.add((a - b).abs());
            }
            for (k, d) in [0.05, 0.1, 0.2].iter().enumerate() {
                beyond[k] += u64::from((p - 0.5).abs() > *d);
            }
        })?;
    }
    println!("curious, {REPS} runs: at each choice after the first");
    println!(
        "  P(recency) {}; |P - 1/2| {}; beyond 0.05 / 0.1 / 0.2: {:.3} / {:.3} / {:.3}",
        p_rec.show(),
        dist.show(),
        beyond[0] as f64 / choices as f64,
        beyond[1] as f64 / choices as f64,
        beyond[2] as f64 / choices as f64
    );
    println!(
        "  both strategies valued at the choice's tiles: {:.3}; |V_rec - V_poi| there {}",
        both as f64 / choices as f64,
        gap.show()
    );
    // 3. The feature r against time: r = max_c r^c counts cells never seen as the
    // stalest (t − t_first + 1 s), so while one is left r is the run's clock.
    let mut rows = Vec::new();
    experiment::trace(&scenario, &options, Mode::Uniform, 0, &mut |v| {
        if v.step % 1000 == 0 {
            let t = v.next.features;
            let unseen = v.map.obstacles().iter().filter(|&&o| o == -1).count();
            let recency = v.map.recency_layer(v.step as f64);
            let seen_r = recency
                .cells
                .iter()
                .zip(v.map.obstacles())
                .filter(|(_, &o)| o != -1)
                .map(|(r, _)| *r)
                .fold(0.0, f64::max);
            rows.push(format!(
                "  t {:>5}: p {:5.1} r {:6.0}; cells never seen {unseen}; r over seen cells {seen_r:.0}",
                v.step, t.p, t.r
            ));
        }
    })?;
    println!("uniform, run 0: the features over time");
    println!("{}", rows.join("\n"));
    if std::env::args().any(|a| a == "--sweep") {
        sweep(&scenario)?;
    }
    Ok(())
}

/// 4. Curious against uniform for a range of τ, episode and feature variants.
fn sweep(scenario: &roam_world::scenario::Scenario) -> Result<(), Box<dyn std::error::Error>> {
    println!("sweep, {REPS} runs per mode: AUC curious vs uniform (recency, poisson)");
    let base = ExperimentOptions {
        repetitions: REPS,
        ..ExperimentOptions::default()
    };
    let mut variants: Vec<(String, ExperimentOptions)> = Vec::new();
    for tau in [2.0, 0.5, 0.2, 0.1, 0.05, 0.02] {
        let mut o = base.clone();
        o.explorer.learner.tau = tau;
        variants.push((format!("tau {tau}"), o));
    }
    for tau in [2.0, 0.1] {
        let mut o = base.clone();
        o.explorer.learner.tau = tau;
        o.explorer.after_random_step = AfterRandomStep::EndEpisode;
        variants.push((format!("end episode early, tau {tau}"), o));
        let mut o = base.clone();
        o.explorer.learner.tau = tau;
        o.explorer.count_discoveries = false;
        variants.push((format!("flips only, tau {tau}"), o));
    }
    for tau in [2.0, 0.5, 0.1] {
        let mut o = base.clone();
        o.explorer.learner.tau = tau;
        o.map.r_over_seen_cells = true;
        variants.push((format!("r over seen cells, tau {tau}"), o));
    }
    for (name, options) in variants {
        let r = experiment::run("grid004", scenario, &options, &|_| {})?;
        // Paired by repetition (the modes share their random numbers): curious − uniform.
        let per_run = |m: Mode| -> Vec<f64> {
            r.runs
                .iter()
                .filter(|x| x.mode == m)
                .map(|x| x.rate_error_auc)
                .collect()
        };
        let mut paired = Stat::default();
        let mut wins = 0;
        let (c, u) = (per_run(Mode::Curious), per_run(Mode::Uniform));
        for (a, b) in c.iter().zip(&u) {
            paired.add(a - b);
            wins += usize::from(a < b);
        }
        let (mut sc, mut su) = (Stat::default(), Stat::default());
        c.iter().for_each(|v| sc.add(*v));
        u.iter().for_each(|v| su.add(*v));
        println!(
            "  {name:<28} curious - uniform per repetition {:+.2} ± {:.2} (unpaired ± {:.2}); curious lower in {wins} of {}",
            paired.mean(),
            paired.se(),
            (sc.se().powi(2) + su.se().powi(2)).sqrt(),
            c.len()
        );
        let auc = |n: &str| {
            r.strategies
                .iter()
                .find(|s| s.name == n)
                .map_or(f64::NAN, |s| s.rate_error_auc)
        };
        let share = r
            .strategies
            .iter()
            .find(|s| s.name == "curious")
            .map_or(f64::NAN, |s| s.recency_share);
        println!(
            "  {name:<28} curious {:.1} uniform {:.1} (recency {:.1}, poisson {:.1}); curious recency share {share:.2}",
            auc("curious"),
            auc("uniform"),
            auc("recency"),
            auc("poisson")
        );
    }
    Ok(())
}
