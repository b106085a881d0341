//! The strategy learner (paper 004 §4): a tile-coded value V_S(p, r) per exploration
//! strategy, updated after each episode with the episode's reward, and a softmax choice
//! of the next strategy.
//!
//! - **Tile coder.** Five tilings over (p/0.5, r/100) (tiles of 0.5 × 100 in feature
//!   units). The paper says the tilings are "randomly displaced" and no more: roam
//!   draws each tiling's offset uniformly in [0, 1) tile in each dimension from the
//!   learner's seed (stream `"tiles"`), so tilings overlap at random fractions of a
//!   tile.
//! - **Bounded table.** Each tiling covers `tiles_p × tiles_r` tiles (default 128 × 128:
//!   p up to 64, r up to 12 800 s); a feature beyond the last tile uses the last tile
//!   (clamping, not hashing: nearby feature values never share a tile by accident). The
//!   table never grows.
//! - **Value.** V_S(p, r) is the *mean* of the active tiles' weights (one per tiling),
//!   so V stays in the units of the reward (map changes per step) and τ = 2.0 means the
//!   same thing whatever the number of tilings. (A sum would make V five times larger
//!   and the softmax almost greedy.)
//! - **Update.** For every (p, r) of the episode's trajectory, in order, each active
//!   tile's weight w ← w(1 − λ) + Rλ with λ = 0.9 (the paper's rule applied per tile).
//!   Weights start at 0.
//! - **Choice.** P(S) ∝ exp(V_S(p, r)/τ), τ = 2.0, at the features of the update that
//!   ends the episode.

use rand::{Rng, RngCore};
use serde::{Deserialize, Serialize};

use crate::error::MapperError;
use crate::features::Features;

/// The most tilings (limit `max_tilings`).
pub const MAX_TILINGS: u32 = 64;
/// The most tiles per tiling (limit `max_tiles_per_tiling`).
pub const MAX_TILES_PER_TILING: u64 = 1 << 20;

/// An exploration strategy (§3): where the next goal is sampled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Strategy {
    /// Recency-based (Thrun): goals where the map was not seen for long, ∝ r^c.
    Recency,
    /// Change-based: goals where a change is likely to have happened, ∝ P_c(E > 0).
    Poisson,
}

impl Strategy {
    pub const ALL: [Strategy; 2] = [Strategy::Recency, Strategy::Poisson];

    pub fn as_str(self) -> &'static str {
        match self {
            Strategy::Recency => "recency",
            Strategy::Poisson => "poisson",
        }
    }

    fn index(self) -> usize {
        match self {
            Strategy::Recency => 0,
            Strategy::Poisson => 1,
        }
    }

    /// Recency when `u` (uniform in [0, 1)) is below `p_recency`. Every mode decides
    /// through this with one draw per episode, so modes that see the same `u` make the
    /// same choice wherever their probabilities are on the same side of it (common
    /// random numbers, see [`crate::experiment`]).
    pub fn pick(p_recency: f64, u: f64) -> Strategy {
        if u < p_recency {
            Strategy::Recency
        } else {
            Strategy::Poisson
        }
    }
}

/// Who picks the strategy. §5 compares the first three; [`Mode::Uniform`] is roam's
/// baseline for the learner: the same mix of strategies with no learning, so a gain of
/// curious over it is the learner's and not the mixing's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// The learner chooses each episode's strategy (curious exploration).
    Curious,
    /// Always recency-based.
    RecencyOnly,
    /// Always change-based.
    PoissonOnly,
    /// Each episode's strategy drawn 50/50, whatever was learned.
    Uniform,
}

impl Mode {
    pub const ALL: [Mode; 4] = [
        Mode::Curious,
        Mode::RecencyOnly,
        Mode::PoissonOnly,
        Mode::Uniform,
    ];

    pub fn as_str(self) -> &'static str {
        match self {
            Mode::Curious => "curious",
            Mode::RecencyOnly => "recency",
            Mode::PoissonOnly => "poisson",
            Mode::Uniform => "uniform",
        }
    }

    /// The strategy the mode forces, `None` for the modes that draw one.
    pub fn forced(self) -> Option<Strategy> {
        match self {
            Mode::Curious | Mode::Uniform => None,
            Mode::RecencyOnly => Some(Strategy::Recency),
            Mode::PoissonOnly => Some(Strategy::Poisson),
        }
    }

    /// P(recency) for an episode: the forced strategy's 1 or 0, 1/2 for the uniform mix
    /// and for curious's first episode (paper 004 §4: "pick a strategy S uniformly at
    /// random"), the learner's softmax at `f` after.
    pub fn recency_probability(self, learner: &Learner, f: Features, first: bool) -> f64 {
        match self {
            Mode::RecencyOnly => 1.0,
            Mode::PoissonOnly => 0.0,
            Mode::Uniform => 0.5,
            Mode::Curious if first => 0.5,
            Mode::Curious => learner.probabilities(f)[0],
        }
    }
}

/// The learner's parameters (the paper's values by default).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LearnerParams {
    /// λ of the update rule, in (0, 1]. Paper: 0.9.
    pub lambda: f64,
    /// τ of the softmax, > 0. Paper: 2.0.
    pub tau: f64,
    /// Number of tilings. Paper: 5.
    pub tilings: u32,
    /// Tile width in p (changes). Paper: 0.5.
    pub tile_p: f64,
    /// Tile width in r (seconds). Paper: 100.
    pub tile_r: f64,
    /// Tiles per tiling along p; larger p values share the last tile.
    pub tiles_p: u32,
    /// Tiles per tiling along r; larger r values share the last tile.
    pub tiles_r: u32,
}

impl Default for LearnerParams {
    fn default() -> Self {
        LearnerParams {
            lambda: 0.9,
            tau: 2.0,
            tilings: 5,
            tile_p: 0.5,
            tile_r: 100.0,
            tiles_p: 128,
            tiles_r: 128,
        }
    }
}

impl LearnerParams {
    pub fn check(&self) -> Result<(), MapperError> {
        let bad = |field: &'static str, reason: String| Err(MapperError::Param { field, reason });
        if !(self.lambda > 0.0 && self.lambda <= 1.0) {
            return bad("lambda", format!("must be in (0, 1], got {}", self.lambda));
        }
        if !(self.tau.is_finite() && self.tau > 0.0) {
            return bad(
                "tau",
                format!("must be a positive number, got {}", self.tau),
            );
        }
        if self.tilings == 0 || self.tilings > MAX_TILINGS {
            return bad(
                "tilings",
                format!(
                    "must be 1 to {MAX_TILINGS} (limit max_tilings), got {}",
                    self.tilings
                ),
            );
        }
        for (field, w) in [("tile_p", self.tile_p), ("tile_r", self.tile_r)] {
            if !(w.is_finite() && w > 0.0) {
                return bad(field, format!("must be a positive width, got {w}"));
            }
        }
        let tiles = u64::from(self.tiles_p) * u64::from(self.tiles_r);
        if self.tiles_p == 0 || self.tiles_r == 0 || tiles > MAX_TILES_PER_TILING {
            return bad(
                "tiles_p",
                format!(
                    "tiles_p x tiles_r must be 1 to {MAX_TILES_PER_TILING} (limit \
                     max_tiles_per_tiling), got {} x {}",
                    self.tiles_p, self.tiles_r
                ),
            );
        }
        Ok(())
    }
}

/// Five (by default) randomly displaced tilings over (p, r).
#[derive(Debug, Clone)]
pub struct TileCoder {
    params: LearnerParams,
    /// Each tiling's offset, in tiles, in [0, 1)².
    offsets: Vec<[f64; 2]>,
}

impl TileCoder {
    /// The tilings, their offsets drawn from `rng` (two uniform draws per tiling).
    pub fn new(params: &LearnerParams, rng: &mut impl RngCore) -> Result<TileCoder, MapperError> {
        params.check()?;
        let offsets = (0..params.tilings)
            .map(|_| [rng.random::<f64>(), rng.random::<f64>()])
            .collect();
        Ok(TileCoder {
            params: *params,
            offsets,
        })
    }

    /// Each tiling's offset in tiles.
    pub fn offsets(&self) -> &[[f64; 2]] {
        &self.offsets
    }

    /// Tiles per tiling.
    pub fn tiles_per_tiling(&self) -> usize {
        self.params.tiles_p as usize * self.params.tiles_r as usize
    }

    /// The active tile of every tiling, as indices into a table of
    /// `tilings × tiles_per_tiling` weights. Negative or non-finite features count as 0.
    pub fn active(&self, f: Features) -> impl Iterator<Item = usize> + '_ {
        let scaled = [
            clean(f.p) / self.params.tile_p,
            clean(f.r) / self.params.tile_r,
        ];
        let per = self.tiles_per_tiling();
        let (np, nr) = (self.params.tiles_p, self.params.tiles_r);
        self.offsets.iter().enumerate().map(move |(k, o)| {
            let ip = tile_index(scaled[0] + o[0], np);
            let ir = tile_index(scaled[1] + o[1], nr);
            k * per + ir * np as usize + ip
        })
    }
}

fn clean(v: f64) -> f64 {
    if v.is_finite() {
        v.max(0.0)
    } else if v > 0.0 {
        f64::MAX
    } else {
        0.0
    }
}

/// floor(x) clamped to [0, n − 1].
fn tile_index(x: f64, n: u32) -> usize {
    let last = n.saturating_sub(1);
    if x >= f64::from(last) {
        last as usize
    } else {
        x.floor().max(0.0) as usize
    }
}

/// V_S for each strategy, its update and the softmax choice.
#[derive(Debug, Clone)]
pub struct Learner {
    params: LearnerParams,
    coder: TileCoder,
    /// One table per strategy, in [`Strategy::ALL`] order.
    weights: [Vec<f64>; 2],
}

impl Learner {
    /// A learner with every weight 0 and its tilings displaced by `rng`.
    pub fn new(params: &LearnerParams, rng: &mut impl RngCore) -> Result<Learner, MapperError> {
        let coder = TileCoder::new(params, rng)?;
        let size = coder.tiles_per_tiling() * params.tilings as usize;
        Ok(Learner {
            params: *params,
            coder,
            weights: [vec![0.0; size], vec![0.0; size]],
        })
    }

    pub fn coder(&self) -> &TileCoder {
        &self.coder
    }

    /// V_S(p, r): the mean weight of the active tiles.
    pub fn value(&self, strategy: Strategy, f: Features) -> f64 {
        let table = &self.weights[strategy.index()];
        let sum: f64 = self
            .coder
            .active(f)
            .map(|i| table.get(i).copied().unwrap_or(0.0))
            .sum();
        sum / f64::from(self.params.tilings)
    }

    /// The paper's update for one episode: for each (p, r) of `trajectory`, each active
    /// tile of `strategy` gets w ← w(1 − λ) + Rλ. A non-finite reward is ignored.
    pub fn update(&mut self, strategy: Strategy, trajectory: &[Features], reward: f64) {
        if !reward.is_finite() {
            return;
        }
        let lambda = self.params.lambda;
        let table = &mut self.weights[strategy.index()];
        for &f in trajectory {
            for i in self.coder.active(f) {
                if let Some(w) = table.get_mut(i) {
                    *w = *w * (1.0 - lambda) + reward * lambda;
                }
            }
        }
    }

    /// P(select S) ∝ exp(V_S(p, r)/τ), in [`Strategy::ALL`] order.
    pub fn probabilities(&self, f: Features) -> [f64; 2] {
        let v = Strategy::ALL.map(|s| self.value(s, f) / self.params.tau);
        let max = v[0].max(v[1]);
        let e = v.map(|x| (x - max).exp());
        let total = e[0] + e[1];
        e.map(|x| x / total)
    }

    /// Draws the next strategy from the softmax (one uniform draw).
    pub fn choose(&self, f: Features, rng: &mut impl RngCore) -> Strategy {
        Strategy::pick(self.probabilities(f)[0], rng.random())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seed::stream;

    fn f(p: f64, r: f64) -> Features {
        Features { p, r }
    }

    #[test]
    fn tiles_follow_the_offsets_and_clamp() {
        let params = LearnerParams {
            tilings: 2,
            tiles_p: 4,
            tiles_r: 3,
            ..LearnerParams::default()
        };
        let mut coder = TileCoder::new(&params, &mut stream(1, "tiles")).expect("coder");
        coder.offsets = vec![[0.0, 0.0], [0.5, 0.25]];
        // p = 0.6 → 1.2 tiles, r = 160 → 1.6 tiles.
        let active: Vec<_> = coder.active(f(0.6, 160.0)).collect();
        // Tiling 0: (1, 1) → 1·4 + 1 = 5. Tiling 1: (1.7 → 1, 1.85 → 1) → 12 + 5 = 17.
        assert_eq!(active, vec![5, 17]);
        // p = 0.8 → 1.6 + 0.5 = 2.1 in tiling 1: tile 2; tiling 0 stays at 1.
        assert_eq!(coder.active(f(0.8, 160.0)).collect::<Vec<_>>(), vec![5, 18]);
        // Far beyond the table: the last tile (3, 2) → 2·4 + 3 = 11 in each tiling.
        assert_eq!(
            coder.active(f(1e9, f64::INFINITY)).collect::<Vec<_>>(),
            vec![11, 23]
        );
        assert_eq!(
            coder.active(f(-3.0, f64::NAN)).collect::<Vec<_>>(),
            vec![0, 12]
        );
    }

    #[test]
    fn offsets_come_from_the_seed() {
        let params = LearnerParams::default();
        let a = TileCoder::new(&params, &mut stream(3, "tiles")).expect("a");
        let b = TileCoder::new(&params, &mut stream(3, "tiles")).expect("b");
        let c = TileCoder::new(&params, &mut stream(4, "tiles")).expect("c");
        assert_eq!(a.offsets(), b.offsets());
        assert_ne!(a.offsets(), c.offsets());
        assert_eq!(a.offsets().len(), 5);
        assert!(a
            .offsets()
            .iter()
            .flatten()
            .all(|&o| (0.0..1.0).contains(&o)));
    }

    #[test]
    fn the_update_rule_by_hand() {
        let mut learner =
            Learner::new(&LearnerParams::default(), &mut stream(0, "tiles")).expect("learner");
        let here = f(1.0, 50.0);
        assert_eq!(learner.value(Strategy::Poisson, here), 0.0);
        // One point, R = 2: every active tile 0·0.1 + 2·0.9 = 1.8.
        learner.update(Strategy::Poisson, &[here], 2.0);
        assert!((learner.value(Strategy::Poisson, here) - 1.8).abs() < 1e-12);
        // The same point twice more with R = 1: 1.8 → 0.18 + 0.9 = 1.08 → 0.108 + 0.9.
        learner.update(Strategy::Poisson, &[here, here], 1.0);
        assert!((learner.value(Strategy::Poisson, here) - 1.008).abs() < 1e-12);
        // The other strategy is untouched; a far point shares no tile.
        assert_eq!(learner.value(Strategy::Recency, here), 0.0);
        assert_eq!(learner.value(Strategy::Poisson, f(30.0, 5000.0)), 0.0);
        // Softmax: V = (0, 1.008), τ = 2: P(recency) = 1 / (1 + e^0.504).
        let p = learner.probabilities(here);
        assert!((p[0] - 1.0 / (1.0 + 0.504f64.exp())).abs() < 1e-12);
        assert!((p[0] + p[1] - 1.0).abs() < 1e-15);
    }

    #[test]
    fn the_choice_follows_the_softmax() {
        let mut learner =
            Learner::new(&LearnerParams::default(), &mut stream(0, "tiles")).expect("learner");
        let here = f(2.0, 300.0);
        learner.update(Strategy::Recency, &[here], 2.0);
        // V = (1.8, 0): P(recency) = 1 / (1 + e^−0.9) ≈ 0.711.
        let want = 1.0 / (1.0 + (-0.9f64).exp());
        let mut rng = stream(9, "choice");
        let n = 20_000;
        let recency = (0..n)
            .filter(|_| learner.choose(here, &mut rng) == Strategy::Recency)
            .count();
        let share = recency as f64 / n as f64;
        // Binomial standard deviation ≈ 0.0032: five of them.
        assert!((share - want).abs() < 0.016, "{share} vs {want}");
    }

    #[test]
    fn bad_parameters_are_refused() {
        let mut rng = stream(0, "tiles");
        for params in [
            LearnerParams {
                lambda: 0.0,
                ..LearnerParams::default()
            },
            LearnerParams {
                tau: -1.0,
                ..LearnerParams::default()
            },
            LearnerParams {
                tilings: 0,
                ..LearnerParams::default()
            },
            LearnerParams {
                tiles_p: 1 << 12,
                tiles_r: 1 << 12,
                ..LearnerParams::default()
            },
            LearnerParams {
                tile_r: f64::NAN,
                ..LearnerParams::default()
            },
        ] {
            assert!(Learner::new(&params, &mut rng).is_err(), "{params:?}");
        }
    }
}
