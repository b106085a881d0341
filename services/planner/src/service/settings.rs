//! The planner's config checked before it starts: the first wrong setting named.

use roam_proto::keys;
use roam_runtime::ServiceError;

use crate::config::PlannerConfig;
use crate::coupling::Coupling;
use crate::queue::MAX_QUEUED_PLANS;

use super::instance::MAX_REQUEST_BYTES;

#[derive(Debug, thiserror::Error)]
pub enum PlannerError {
    #[error(transparent)]
    Service(#[from] ServiceError),
    #[error("invalid config: {0}")]
    Config(String),
    #[error("invalid config: {0}")]
    Setting(#[from] SettingError),
}

/// A config setting outside its range: its name (as in the config file), the value
/// and what is allowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{name} = {value} is out of range; use {allowed}")]
pub struct SettingError {
    pub name: &'static str,
    pub value: String,
    pub allowed: String,
}

/// Checks the config's numbers; names the first that is wrong.
pub fn check_config(config: &PlannerConfig) -> Result<(), PlannerError> {
    if config.max_concurrent_plans == 0 {
        return Err(PlannerError::Config(
            "max_concurrent_plans must be at least 1".into(),
        ));
    }
    if !(1..=MAX_QUEUED_PLANS).contains(&config.max_queued_plans) {
        return Err(SettingError {
            name: "max_queued_plans",
            value: config.max_queued_plans.to_string(),
            allowed: format!(
                "1..={MAX_QUEUED_PLANS} requests (each holds up to {} KiB while it waits)",
                MAX_REQUEST_BYTES / 1024
            ),
        }
        .into());
    }
    for (name, value) in [
        ("max_plan_cost", config.max_plan_cost),
        ("max_population_cells", config.max_population_cells),
    ] {
        if value == 0 {
            return Err(PlannerError::Config(format!("{name} must be at least 1")));
        }
    }
    config.budget().validate().map_err(PlannerError::Config)?;
    if let Some(value) = config.planning_resolution_m {
        use crate::resolution::MAX_PLANNING_RESOLUTION_M;
        if !(value.is_finite() && value > 0.0 && value <= MAX_PLANNING_RESOLUTION_M) {
            return Err(SettingError {
                name: crate::resolution::LIMIT_NAME,
                value: value.to_string(),
                allowed: format!("(0, {MAX_PLANNING_RESOLUTION_M}] metres, at least the map's resolution (paper 000: 0.2), or leave it out"),
            }
            .into());
        }
    }
    keys::check_name("information_layer", &config.information_layer)
        .map_err(|e| PlannerError::Config(e.to_string()))?;
    if config.coupling != Coupling::Max && config.change_layer.is_none() {
        return Err(PlannerError::Config(format!(
            "coupling: {} needs a change_layer to couple (the mapper's news layer): set change_layer: news, or leave coupling out",
            config.coupling.as_str()
        )));
    }
    if !crate::coupling::is_news_floor(config.news_floor) {
        return Err(SettingError {
            name: crate::coupling::NEWS_FLOOR_NAME,
            value: config.news_floor.to_string(),
            allowed: format!(
                "a share from 0 to 1 (default {})",
                crate::coupling::DEFAULT_NEWS_FLOOR
            ),
        }
        .into());
    }
    if let Some(obstacles) = &config.obstacles_layer {
        keys::check_name("obstacles_layer", obstacles)
            .map_err(|e| PlannerError::Config(e.to_string()))?;
    }
    let inflation = config.obstacle_inflation_m;
    let most = crate::seen::MAX_OBSTACLE_INFLATION_M;
    if !(inflation.is_finite() && (0.0..=most).contains(&inflation)) {
        return Err(SettingError {
            name: "obstacle_inflation_m",
            value: inflation.to_string(),
            allowed: format!("0 to {most} metres"),
        }
        .into());
    }
    if let Some(change) = &config.change_layer {
        keys::check_name("change_layer", change)
            .map_err(|e| PlannerError::Config(e.to_string()))?;
        if *change == config.information_layer {
            return Err(PlannerError::Config(format!(
                "change_layer {change:?} is the information layer itself; name the mapper's change layer (change_information) or leave it out"
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_news_coupling_needs_a_change_layer() {
        let alone = PlannerConfig {
            coupling: Coupling::News,
            ..PlannerConfig::default()
        };
        match check_config(&alone) {
            Err(PlannerError::Config(e)) => {
                assert!(
                    e.contains("coupling: news") && e.contains("change_layer"),
                    "{e}"
                )
            }
            other => panic!("{other:?}"),
        }
        let paired = PlannerConfig {
            change_layer: Some("news".into()),
            ..alone
        };
        assert!(check_config(&paired).is_ok());
    }

    #[test]
    fn a_news_floor_outside_zero_to_one_is_refused_by_name() {
        for floor in [-0.1, 1.5, f64::NAN, f64::INFINITY] {
            let config = PlannerConfig {
                news_floor: floor,
                ..PlannerConfig::default()
            };
            let e = check_config(&config).expect_err("refused").to_string();
            assert!(e.contains("news_floor") && e.contains("0 to 1"), "{e}");
        }
        for floor in [0.0, 0.25, 1.0] {
            let config = PlannerConfig {
                news_floor: floor,
                ..PlannerConfig::default()
            };
            assert!(check_config(&config).is_ok(), "{floor}");
        }
    }
}
