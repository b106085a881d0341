//! The learner's two features (paper 004 §4), p = Σ_c P_c(E > 0) and r = max_c r^c,
//! kept cheap enough for a large map observed many times a second.
//!
//! Summing Eq. 2 over a million cells at every update costs a million `exp`s. Instead
//! the map is cut into tiles of [`TILE_CELLS`]² cells and each tile keeps:
//!
//! - the list of its *active* cells, those with at least one event (the others have
//!   rate 0 and P = 0 and cost nothing); at most a tile's area, so it is bounded;
//! - for p, a cache taken at a time t_c: the count of active cells already *saturated*
//!   (λΔ ≥ 37.5, where 1 − e^(−λΔ) rounds to exactly 1.0 in f64 and stays there), and
//!   for the others (weights w_i = e^(−λ_i Δ_i(t_c))) the scaled moments
//!   M_k = Σ_i w_i (λ_i/λ_max)^k / k!, k < [`TAYLOR_TERMS`]. At a later t = t_c + δ,
//!   Σ_i P_i(t) = n_sat + n_unsat − Σ_k M_k (−λ_max δ)^k, a polynomial of 20 terms
//!   whatever the number of cells. The truncation error is below
//!   (λ_max δ)^20 / 20! ≤ 4.3·10⁻¹³ per cell while λ_max δ ≤ [`TAYLOR_RADIUS`] = 2;
//!   beyond that, or when the tile was observed since t_c (rates and t_last changed),
//!   the cache is rebuilt exactly at t (one `exp` per unsaturated active cell);
//! - for r, the minimum t_last over its seen cells, rebuilt when observed.
//!
//! The trade-off: a query costs O(tiles) plus the rebuilds, and a tile is rebuilt at
//! most once per observation of it and once every 2/λ_max seconds otherwise, while the
//! answer stays exact to ~10⁻¹² relative (tests compare it with the plain sum). Memory:
//! 20 floats per tile. Cells that never changed are never visited.

use serde::Serialize;

use crate::poisson::CellProcess;

/// Tile side in cells.
pub const TILE_CELLS: u32 = 64;
/// Terms of the Taylor series of e^(−λδ) kept per tile.
pub const TAYLOR_TERMS: usize = 20;
/// The largest λ_max·δ the series is used for before the tile is rebuilt.
pub const TAYLOR_RADIUS: f64 = 2.0;
/// λΔ from which 1 − e^(−λΔ) is exactly 1.0 in f64 (e^(−37.5) ≈ 5.2·10⁻¹⁷ < 2⁻⁵⁴).
const SATURATED: f64 = 37.5;

/// The learner's features (paper 004 §4, Eq. 4): both non-negative.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Features {
    /// p = Σ_c P_c(E > 0): how many changes are expected to have gone unseen.
    pub p: f64,
    /// r = max_c r^c, seconds: how long the least recently seen cell has not been seen.
    pub r: f64,
}

#[derive(Debug, Clone)]
struct Tile {
    x0: u32,
    y0: u32,
    width: u32,
    height: u32,
    /// Global indices of the tile's cells that have at least one event.
    active: Vec<u32>,
    /// Observed since the caches were built.
    dirty: bool,
    /// The time the probability cache is for.
    cache_t: f64,
    n_saturated: u32,
    n_unsaturated: u32,
    lambda_max: f64,
    /// M_k / k! as in the module doc.
    coefficients: [f64; TAYLOR_TERMS],
    /// The smallest t_last over the tile's seen cells; +∞ when none is seen.
    min_t_last: f64,
}

/// The per-tile caches of a map.
#[derive(Debug, Clone)]
pub(crate) struct TileCache {
    map_width: u32,
    tiles_x: u32,
    tiles: Vec<Tile>,
    /// (λ, w) of a tile's unsaturated cells while it is rebuilt (at most a tile's area).
    scratch: Vec<(f64, f64)>,
    /// 1/k!.
    inverse_factorial: [f64; TAYLOR_TERMS],
}

impl TileCache {
    pub(crate) fn new(width: u32, height: u32) -> TileCache {
        let tiles_x = width.div_ceil(TILE_CELLS);
        let tiles_y = height.div_ceil(TILE_CELLS);
        let mut tiles = Vec::with_capacity((tiles_x * tiles_y) as usize);
        for ty in 0..tiles_y {
            for tx in 0..tiles_x {
                let (x0, y0) = (tx * TILE_CELLS, ty * TILE_CELLS);
                tiles.push(Tile {
                    x0,
                    y0,
                    width: TILE_CELLS.min(width - x0),
                    height: TILE_CELLS.min(height - y0),
                    active: Vec::new(),
                    dirty: false,
                    cache_t: 0.0,
                    n_saturated: 0,
                    n_unsaturated: 0,
                    lambda_max: 0.0,
                    coefficients: [0.0; TAYLOR_TERMS],
                    min_t_last: f64::INFINITY,
                });
            }
        }
        let mut inverse_factorial = [1.0; TAYLOR_TERMS];
        for k in 1..TAYLOR_TERMS {
            inverse_factorial[k] = inverse_factorial[k - 1] / k as f64;
        }
        TileCache {
            map_width: width,
            tiles_x,
            tiles,
            scratch: Vec::new(),
            inverse_factorial,
        }
    }

    fn tile_of(&self, x: u32, y: u32) -> usize {
        ((y / TILE_CELLS) * self.tiles_x + x / TILE_CELLS) as usize
    }

    /// Marks every tile the rectangle touches as observed.
    pub(crate) fn mark(&mut self, x0: u32, y0: u32, width: u32, height: u32) {
        if width == 0 || height == 0 {
            return;
        }
        for ty in y0 / TILE_CELLS..=(y0 + height - 1) / TILE_CELLS {
            for tx in x0 / TILE_CELLS..=(x0 + width - 1) / TILE_CELLS {
                if let Some(tile) = self.tiles.get_mut((ty * self.tiles_x + tx) as usize) {
                    tile.dirty = true;
                }
            }
        }
    }

    /// Adds a cell that just had its first event to its tile's active list.
    pub(crate) fn activate(&mut self, x: u32, y: u32) {
        let t = self.tile_of(x, y);
        let index = y * self.map_width + x;
        if let Some(tile) = self.tiles.get_mut(t) {
            tile.active.push(index);
            tile.dirty = true;
        }
    }

    /// How many cells have at least one event.
    pub(crate) fn active_cells(&self) -> usize {
        self.tiles.iter().map(|t| t.active.len()).sum()
    }

    /// p and the smallest t_last over seen cells (+∞ if none), at `t`, refreshing the
    /// caches that need it.
    pub(crate) fn refresh(&mut self, cells: &[CellProcess], t: f64) -> (f64, f64) {
        let (mut p, mut min_t_last) = (0.0, f64::INFINITY);
        let inverse_factorial = self.inverse_factorial;
        for tile in &mut self.tiles {
            if tile.dirty {
                tile.min_t_last = tile_min_t_last(tile, cells, self.map_width);
            }
            min_t_last = min_t_last.min(tile.min_t_last);
            if tile.active.is_empty() {
                tile.dirty = false;
                continue;
            }
            let delta = t - tile.cache_t;
            // Saturation only holds forward in time: an earlier query always rebuilds.
            let stale =
                delta < 0.0 || (tile.n_unsaturated > 0 && tile.lambda_max * delta > TAYLOR_RADIUS);
            if tile.dirty || stale {
                rebuild(tile, cells, t, &mut self.scratch, &inverse_factorial);
            }
            tile.dirty = false;
            p += tile_probability(tile, t);
        }
        (p, min_t_last)
    }
}

/// The smallest t_last over a tile's seen cells.
fn tile_min_t_last(tile: &Tile, cells: &[CellProcess], map_width: u32) -> f64 {
    let mut min = f64::INFINITY;
    for y in tile.y0..tile.y0 + tile.height {
        let row = (y * map_width + tile.x0) as usize;
        for c in cells.iter().skip(row).take(tile.width as usize) {
            if let Some(t_last) = c.t_last() {
                min = min.min(t_last);
            }
        }
    }
    min
}

/// Rebuilds a tile's probability cache exactly at `t`.
fn rebuild(
    tile: &mut Tile,
    cells: &[CellProcess],
    t: f64,
    scratch: &mut Vec<(f64, f64)>,
    inverse_factorial: &[f64; TAYLOR_TERMS],
) {
    scratch.clear();
    let mut n_saturated = 0;
    let mut lambda_max: f64 = 0.0;
    for &i in &tile.active {
        let Some(c) = cells.get(i as usize) else {
            continue;
        };
        let lambda = c.rate();
        let elapsed = c.t_last().map_or(0.0, |t_last| (t - t_last).max(0.0));
        let x = lambda * elapsed;
        if x >= SATURATED {
            n_saturated += 1;
        } else {
            scratch.push((lambda, (-x).exp()));
            lambda_max = lambda_max.max(lambda);
        }
    }
    let mut moments = [0.0; TAYLOR_TERMS];
    for &(lambda, w) in scratch.iter() {
        let ratio = if lambda_max > 0.0 {
            lambda / lambda_max
        } else {
            0.0
        };
        let mut term = w;
        for m in &mut moments {
            *m += term;
            term *= ratio;
        }
    }
    for (m, f) in moments.iter_mut().zip(inverse_factorial) {
        *m *= f;
    }
    tile.cache_t = t;
    tile.n_saturated = n_saturated;
    tile.n_unsaturated = scratch.len() as u32;
    tile.lambda_max = lambda_max;
    tile.coefficients = moments;
}

/// Σ P over a tile's active cells at `t` from its cache (`t` within the radius).
fn tile_probability(tile: &Tile, t: f64) -> f64 {
    if tile.n_unsaturated == 0 {
        return f64::from(tile.n_saturated);
    }
    let z = -tile.lambda_max * (t - tile.cache_t);
    let unchanged = tile
        .coefficients
        .iter()
        .rev()
        .fold(0.0, |acc, &c| acc * z + c);
    let p = f64::from(tile.n_saturated) + f64::from(tile.n_unsaturated) - unchanged;
    p.max(0.0)
}
