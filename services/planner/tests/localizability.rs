//! The localizability cost (roam's W_loc, paper 002's PEB in paper 000's fitness): plans
//! keep out of cells without a fix, and a forgiven PEB costs nothing where the floor is
//! covered.

mod common;

use common::{check_geometry, run, small_spec};
use roam_planner::world::World;
use roam_proto::planner::PlannerModel;

/// An open 60 × 40 world with a band of unbounded PEB (no fix) across the middle, 2 m
/// wide, except a gap at the top; elsewhere 0.1 m.
fn world_with_a_band_without_a_fix() -> World {
    let mut world = common::open_world(60, 40);
    let (w, h) = (world.width(), world.height());
    let mut peb = vec![0.1f32; w * h];
    for y in 0..h - 6 {
        for x in 25..35 {
            peb[y * w + x] = f32::INFINITY;
        }
    }
    world.set_localizability(&peb);
    world
}

/// roam's coupling of paper 002 into paper 000: with W_loc > 0 the fitness pays for the
/// PEB along the path (f6 = −W_loc · Σ PEB over the genes' cells), so the plan keeps out
/// of a band where localization is poor; with W_loc = 0 nothing changes.
#[test]
fn the_localizability_cost_keeps_plans_out_of_poorly_covered_cells() {
    let world = world_with_a_band_without_a_fix();
    let cost_along = |path: &[u32]| -> f64 {
        path.iter()
            .map(|&c| f64::from(world.localizability[c as usize]))
            .sum()
    };
    let base = small_spec(PlannerModel::Model1, [1.0, 2.0], [11.0, 2.0], 60.0, 5, 800);
    let free = run(&world, &base);
    assert_eq!(free.fitness.f6_localizability, 0.0, "off by default");
    let mut costed_spec = base.clone();
    costed_spec.params.w_loc = 20_000.0;
    let costed = run(&world, &costed_spec);
    check_geometry(&world, &costed_spec, &costed);
    let along = cost_along(&costed.path);
    assert!(
        (costed.fitness.f6_localizability + 20_000.0 * along).abs() < 1e-6 * along.max(1.0),
        "f6 {} against -W_loc * {along}",
        costed.fitness.f6_localizability
    );
    assert!(
        along < cost_along(&free.path),
        "the costed plan crosses {along} m of PEB, the free one {}",
        cost_along(&free.path)
    );
}

/// `peb_free_m` forgives the PEB below it: a plan costs W_loc · Σ max(0, PEB −
/// peb_free_m), nothing where the floor is covered (0.1 m < 0.5 m), the capped PEB
/// less 0.5 m in the band without a fix; a negative value is refused.
#[test]
fn the_forgiven_peb_costs_nothing_where_the_floor_is_covered() {
    let world = world_with_a_band_without_a_fix();
    let mut s = small_spec(PlannerModel::Model1, [1.0, 2.0], [11.0, 2.0], 60.0, 5, 800);
    s.params.w_loc = 20_000.0;
    s.params.peb_free_m = 0.5;
    let forgiven = run(&world, &s);
    check_geometry(&world, &s, &forgiven);
    let excess: f64 = forgiven
        .path
        .iter()
        .map(|&c| (f64::from(world.localizability[c as usize]) - 0.5).max(0.0))
        .sum();
    assert!(
        (forgiven.fitness.f6_localizability + 20_000.0 * excess).abs() < 1e-6 * excess.max(1.0),
        "f6 {} against -W_loc * {excess}",
        forgiven.fitness.f6_localizability
    );
    // Only the band's cells cost, each its capped PEB less the forgiven 0.5 m; the
    // covered cells (0.1 m) nothing.
    let capped = f64::from(roam_planner::world::MAX_LOCALIZABILITY_COST_M);
    let in_band = forgiven
        .path
        .iter()
        .filter(|&&c| f64::from(world.localizability[c as usize]) > 0.5)
        .count();
    assert!(
        (excess - in_band as f64 * (capped - 0.5)).abs() < 1e-9,
        "{excess} m over {in_band} cells in the band"
    );
    assert!(
        forgiven.path.len() > in_band,
        "covered cells on the path too"
    );
    let mut bad = s.params.clone();
    bad.peb_free_m = -1.0;
    assert!(
        bad.validate().is_err(),
        "a negative forgiven PEB is refused"
    );
}
