//! Paper 002's point robot is what it was before the unicycle came: a seeded run's whole
//! report stream (positions, ranges, observations, events) and its snapshot hash to the
//! values the sim gave at commit 1ffa85a, the last one without the unicycle.

mod common;

use roam_sim::{Command, Sim};
use roam_world::seed::fnv1a;

/// Drives every robot for `steps`: slow circles, some commands beyond the top speed,
/// some steps without a command, so that clipping, collisions and standing still are
/// all in the stream. Returns the hash of the reports and of the final snapshot, both as
/// JSON (serde_json writes every f64 so that it reads back bit for bit).
fn run(sim: &mut Sim, steps: u32) -> (u64, u64) {
    let names: Vec<String> = sim.robots().map(|r| r.name().to_owned()).collect();
    let mut reports = Vec::new();
    for k in 0..steps {
        let commands: Vec<Command> = names
            .iter()
            .enumerate()
            .filter(|_| k % 17 != 5)
            .map(|(i, name)| {
                let a = f64::from(k) * 0.07 + i as f64;
                let gain = if k % 11 < 3 { 4.0 } else { 1.0 };
                Command {
                    robot: name.clone(),
                    u: [gain * a.cos(), gain * a.sin()],
                }
            })
            .collect();
        reports.push(sim.step(&commands).expect("step"));
    }
    let stream = serde_json::to_vec(&reports).expect("json");
    let text = String::from_utf8_lossy(&stream);
    assert!(text.contains("speed_clipped"), "the run clips speeds");
    assert!(
        sim.anchors().is_empty() || text.contains("\"ranges\":[{"),
        "the run measures ranges"
    );
    let snapshot = serde_json::to_vec(&sim.snapshot("fingerprint")).expect("json");
    (fnv1a(&stream), fnv1a(&snapshot))
}

#[test]
fn a_seeded_point_robot_run_is_unchanged_bit_for_bit() {
    let mut room = Sim::new(&common::inline(common::ROOM), 42).expect("sim");
    let mut downtime = Sim::new(&common::shipped("downtime.yaml"), 7).expect("sim");
    let mut grid = Sim::new(&common::shipped("grid004.yaml"), 3).expect("sim");
    let got = [
        run(&mut room, 400),
        run(&mut downtime, 300),
        run(&mut grid, 200),
    ];
    let collided = |sim: &mut Sim| {
        sim.reset(42);
        (0..60).any(|_| {
            let u = [4.0, 0.0];
            let report = sim
                .step(&[Command {
                    robot: "r1".into(),
                    u,
                }])
                .expect("step");
            report.robots[0]
                .events
                .iter()
                .any(|e| matches!(e, roam_sim::Event::Collision { .. }))
        })
    };
    assert!(collided(&mut room), "the room's robots reach its walls");
    println!("{got:#018x?}");
    assert_eq!(got, EXPECTED);
}

/// What the sim at commit 1ffa85a gave for the three runs above.
const EXPECTED: [(u64, u64); 3] = [
    (0x6495_ab5a_5987_b061, 0x822f_69cb_d842_87c2),
    (0x8e13_b387_ec83_564b, 0x549e_befa_f78e_cdcd),
    (0x16aa_7026_a834_7fa9, 0x0e7b_3413_9527_5b10),
];
