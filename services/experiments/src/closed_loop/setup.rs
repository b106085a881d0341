//! What a closed-loop run starts from, shared by a whole run ([`super::episode`]) and
//! a step at a time ([`super::stepper`]): the scenario made ready ([`Setup`]), where the
//! controller's position comes from ([`PositionSource`]), and what cannot start
//! ([`EpisodeError`]).

use std::sync::Arc;

use roam_controller::information::InformationField;
use roam_controller::obstacle_field::ObstacleField;
use roam_controller::params::ParamError;
use roam_localization::fim::FimOptions;
use roam_localization::model::RangingModel;
use roam_localization::LocalizationError;
use roam_sim::{SimError, SimParams};
use roam_world::scenario::Scenario;
use serde::Serialize;

/// Where the controller's position comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PositionSource {
    /// The localization estimate and its PEB (paper 002 ES1, ES3).
    Estimate,
    /// The true position and the PEB there (paper 002 ES2: "nominal conditions").
    Truth,
}

/// What an episode cannot start with.
#[derive(Debug, thiserror::Error)]
pub enum EpisodeError {
    #[error("the sim refused the scenario: {0}")]
    Sim(#[from] SimError),
    #[error("the scenario's sensing model is unusable: {0}")]
    Model(#[from] LocalizationError),
    #[error(transparent)]
    Params(#[from] ParamError),
    #[error("a mission names robot '{0}', which the scenario does not have")]
    UnknownRobot(String),
    #[error("robot '{0}' has two missions")]
    DuplicateMission(String),
    #[error(transparent)]
    Scenario(#[from] roam_world::scenario::ScenarioError),
    #[error("scenario {0} has no robot")]
    NoRobot(String),
}

/// A scenario made ready for many episodes: the sim's parameters and the two fields,
/// built once.
#[derive(Debug, Clone)]
pub struct Setup {
    pub scenario: Scenario,
    pub sim_params: SimParams,
    pub obstacles: Arc<ObstacleField>,
    pub information: Arc<InformationField>,
}

impl Setup {
    /// The scenario's sim parameters without the observation (module doc), its obstacle
    /// field, and its anchors' information field with default [`FimOptions`].
    pub fn new(scenario: &Scenario) -> Result<Setup, EpisodeError> {
        let mut sim_params = SimParams::from_file(&scenario.file);
        sim_params.sensing.observation_radius_m = 0.0;
        sim_params.check(scenario.occupancy.meta.resolution)?;
        let anchors: Vec<[f64; 2]> = scenario.file.anchors.iter().map(|a| a.at).collect();
        let model = RangingModel::from_spec(&anchors, &scenario.file.sensing)?;
        Ok(Setup {
            scenario: scenario.clone(),
            sim_params,
            obstacles: Arc::new(ObstacleField::new(&scenario.occupancy)),
            information: Arc::new(InformationField::new(model, FimOptions::default())),
        })
    }

    /// The scenario's start of robot `name`.
    pub fn start_of(&self, name: &str) -> Option<[f64; 2]> {
        self.scenario
            .file
            .robots
            .iter()
            .find(|r| r.name == name)
            .map(|r| r.at)
    }
}
