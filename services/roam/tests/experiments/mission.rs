//! `roam reproduce mission` and its batch of days: the couplings, every variant's windows
//! and goals with verdicts.

use super::*;

#[test]
fn reproduce_mission_compares_the_couplings() {
    let (value, _) = run_json(
        &[
            "reproduce",
            "mission",
            "--json",
            "--missions",
            "1",
            "--generations",
            "50",
        ],
        None,
    );
    let variants: Vec<&str> = value["variants"]
        .as_array()
        .expect("variants")
        .iter()
        .filter_map(|v| v["variant"].as_str())
        .collect();
    assert_eq!(variants, ["static", "peb_cost", "change", "shortest"]);
    for v in value["variants"].as_array().expect("variants") {
        assert!(v["information"].as_f64().expect("information") > 0.0);
        let share = v["on_time_share"].as_f64().expect("share");
        assert!((0.0..=1.0).contains(&share));
        assert!(v["peb_mean_m"].as_f64().expect("peb") > 0.0);
    }
    // Every joining claim is judged, by the rule, from the figures above.
    let claims = value["claims"].as_array().expect("claims");
    assert_eq!(claims.len(), 5, "{claims:?}");
    for c in claims {
        let verdict = c["verdict"].as_str().expect("verdict");
        assert!(
            ["holds", "does_not_hold", "no_data"].contains(&verdict),
            "{c}"
        );
        assert!(!c["ours"].as_str().expect("ours").is_empty(), "{c}");
    }
    let on_time = value["variants"][0]["on_time_share"]
        .as_f64()
        .expect("share");
    let judged = claims
        .iter()
        .find(|c| {
            c["claim"]
                .as_str()
                .is_some_and(|t| t.contains("within its budget"))
        })
        .expect("the budget claim");
    assert_eq!(judged["verdict"] == "holds", on_time >= 1.0, "{judged}");
}

#[test]
fn reproduce_mission_days_reports_every_variant_window_and_goal_with_a_verdict() {
    let (value, stderr) = run_json(
        &[
            "reproduce",
            "mission",
            "--json",
            "--days",
            "2",
            "--generations",
            "20",
            "--jobs",
            "2",
        ],
        None,
    );
    assert_eq!(value["days"], 2);
    let variants: Vec<&str> = value["variants"]
        .as_array()
        .expect("variants")
        .iter()
        .filter_map(|v| v["variant"].as_str())
        .collect();
    assert_eq!(
        variants,
        ["plain", "executive", "no_change", "no_peb", "fastest_path"]
    );
    for v in value["variants"].as_array().expect("variants") {
        assert_eq!(v["days"], 2);
        assert_eq!(v["windows"], 8, "four windows a day: {v}");
        let share = v["share_median"].as_f64().expect("share");
        assert!((0.0..=1.0).contains(&share), "{share}");
        assert_eq!(v["by_window"].as_array().expect("by window").len(), 4);
    }
    // Every goal has a figure, a threshold and a verdict, and a shortfall exactly when
    // it does not hold.
    let goals = value["goals"].as_array().expect("goals");
    assert_eq!(goals.len(), 6);
    for g in goals {
        assert!(g["figure"].is_number(), "{g}");
        assert!(g["threshold"].is_number(), "{g}");
        let verdict = g["verdict"].as_str().expect("verdict");
        assert!(["holds", "does_not_hold"].contains(&verdict), "{g}");
        assert_eq!(
            g["shortfall"].is_string(),
            verdict == "does_not_hold",
            "{g}"
        );
    }
    let effects: Vec<&str> = value["effects"]
        .as_array()
        .expect("effects")
        .iter()
        .filter_map(|e| e["coupling"].as_str())
        .collect();
    assert_eq!(effects, ["change", "peb"]);
    assert_eq!(value["results"].as_array().expect("results").len(), 10);
    assert!(stderr.contains("2 days x 5 variants"), "{stderr}");
}
