use super::*;
use roam_proto::localization::{PebAt, PebQuery, PebReply, PebWhere, PositionEstimate};
use roam_proto::sim::NamedPoint;

fn matrix() -> impl Strategy<Value = [[f64; 2]; 2]> {
    [[finite(), finite()], [finite(), finite()]]
}

proptest! {
    #[test]
    fn estimate_round_trips(robot in name(), step in any::<u64>(), p in [finite(), finite()], crb in prop::option::of(matrix()), peb in prop::option::of(0.0..1e3f64), used in prop::collection::vec(name(), 0..5), degraded in any::<bool>()) {
        round_trips(&PositionEstimate { robot, step, time_s: 1.5, position: p, crb, peb_m: peb, anchors_used: used, degraded });
    }

    #[test]
    fn peb_query_and_reply_round_trip(points in prop::collection::vec([finite(), finite()], 0..8), m in meta(), anchors in prop::option::of(prop::collection::vec((name(), [finite(), finite()]), 0..4)), gradient in any::<bool>(), cells in prop::collection::vec(0.0..100.0f32, 0..30)) {
        let anchors = anchors.map(|a| a.into_iter().map(|(name, at)| NamedPoint { name, at }).collect());
        round_trips(&PebQuery { at: PebWhere::Points(points.clone()), anchors: anchors.clone(), gradient, crb: false });
        round_trips(&PebQuery { at: PebWhere::Region(m), anchors, gradient: false, crb: gradient });
        round_trips(&PebReply::Points(points.iter().map(|&at| PebAt { at, peb_m: Some(1.0), crb: None, gradient: Some([0.1, -0.2]) }).collect()));
        round_trips(&PebReply::Field { meta: m, cells: Cells::F32(cells.clone()), crb: None });
        round_trips(&PebReply::Field { meta: m, cells: Cells::F32(cells.clone()), crb: Some(roam_proto::localization::CrbCells { xx: Cells::F32(cells.clone()), xy: Cells::F32(cells.clone()), yy: Cells::F32(cells) }) });
    }
}
