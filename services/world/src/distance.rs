//! Exact Euclidean distance transform (Felzenszwalb & Huttenlocher, "Distance Transforms
//! of Sampled Functions", 2012): two passes of the 1-D lower-envelope algorithm, O(cells).
//! Inflation uses it here; the controller's repulsive force will use it too.

/// Squared distance, in cells², from every cell to the nearest cell where `is_source`
/// is true. With no source at all every value is `f32::INFINITY`.
pub fn squared_distance(
    width: usize,
    height: usize,
    is_source: impl Fn(usize) -> bool,
) -> Vec<f32> {
    let mut d: Vec<f32> = (0..width * height)
        .map(|i| if is_source(i) { 0.0 } else { f32::INFINITY })
        .collect();
    let longest = width.max(height);
    let mut line = vec![0.0f32; longest];
    let mut out = vec![0.0f32; longest];
    let mut hull = vec![0usize; longest];
    let mut bounds = vec![0.0f32; longest + 1];
    // Columns first, then rows.
    for x in 0..width {
        for y in 0..height {
            line[y] = d[y * width + x];
        }
        transform_line(&line[..height], &mut out[..height], &mut hull, &mut bounds);
        for y in 0..height {
            d[y * width + x] = out[y];
        }
    }
    for y in 0..height {
        let row = &mut d[y * width..(y + 1) * width];
        line[..width].copy_from_slice(row);
        transform_line(&line[..width], &mut out[..width], &mut hull, &mut bounds);
        row.copy_from_slice(&out[..width]);
    }
    d
}

/// The 1-D squared distance transform of `f` into `out`.
fn transform_line(f: &[f32], out: &mut [f32], hull: &mut [usize], bounds: &mut [f32]) {
    let n = f.len();
    // Parabolas rooted at finite samples only; with none, everything stays infinite.
    let mut k: isize = -1;
    for q in 0..n {
        if !f[q].is_finite() {
            continue;
        }
        let qf = q as f32;
        loop {
            if k < 0 {
                k = 0;
                hull[0] = q;
                bounds[0] = f32::NEG_INFINITY;
                bounds[1] = f32::INFINITY;
                break;
            }
            let v = hull[k as usize];
            let vf = v as f32;
            let s = ((f[q] + qf * qf) - (f[v] + vf * vf)) / (2.0 * qf - 2.0 * vf);
            if s <= bounds[k as usize] {
                k -= 1;
                continue;
            }
            k += 1;
            hull[k as usize] = q;
            bounds[k as usize] = s;
            bounds[k as usize + 1] = f32::INFINITY;
            break;
        }
    }
    if k < 0 {
        out.fill(f32::INFINITY);
        return;
    }
    let mut j = 0usize;
    for (q, slot) in out.iter_mut().enumerate() {
        let qf = q as f32;
        while bounds[j + 1] < qf {
            j += 1;
        }
        let v = hull[j];
        let dv = qf - v as f32;
        *slot = dv * dv + f[v];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn brute_force(width: usize, height: usize, sources: &[bool]) -> Vec<f32> {
        (0..width * height)
            .map(|i| {
                let (x, y) = ((i % width) as f32, (i / width) as f32);
                sources
                    .iter()
                    .enumerate()
                    .filter(|(_, s)| **s)
                    .map(|(j, _)| {
                        let (sx, sy) = ((j % width) as f32, (j / width) as f32);
                        (x - sx).powi(2) + (y - sy).powi(2)
                    })
                    .fold(f32::INFINITY, f32::min)
            })
            .collect()
    }

    proptest! {
        #[test]
        fn matches_brute_force(width in 1usize..12, height in 1usize..12, seed in prop::collection::vec(any::<bool>(), 144)) {
            let sources: Vec<bool> = (0..width * height).map(|i| seed[i] && seed[(i * 7) % 144]).collect();
            let fast = squared_distance(width, height, |i| sources[i]);
            prop_assert_eq!(fast, brute_force(width, height, &sources));
        }
    }
}
