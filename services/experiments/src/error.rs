//! What an experiment can fail with.

use crate::reproduce::apf::render::RenderError;
use crate::reproduce::apf::ApfError;
use crate::reproduce::mapper::experiment::MappingError;
use crate::reproduce::mapper::truth::TruthError;
use crate::reproduce::mission::days::DaysError;
use crate::reproduce::mission::missions::MissionExperimentError;

/// An experiment that could not run to its end. Each says what was being
/// set up or asked, so the fix is in the message; each experiment's own error says
/// which of its options or inputs was refused.
#[derive(Debug, thiserror::Error)]
pub enum ExperimentError {
    /// The world, a scenario, a service or an output directory could not be made ready.
    #[error("{0}")]
    Setup(String),
    /// A closed-loop run could not be set up or stepped.
    #[error(transparent)]
    Episode(#[from] crate::closed_loop::EpisodeError),
    /// Paper 002's experiments (ES1–ES3).
    #[error(transparent)]
    Apf(#[from] ApfError),
    /// A picture could not be written.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// Paper 004's experiment.
    #[error(transparent)]
    Mapping(#[from] MappingError),
    /// The true change rates of a scripted world.
    #[error(transparent)]
    Truth(#[from] TruthError),
    /// The papers joined, mission by mission.
    #[error(transparent)]
    Missions(#[from] MissionExperimentError),
    /// The executive's day in batch.
    #[error(transparent)]
    Days(#[from] DaysError),
    /// A scenario shipped with roam or named on the command line.
    #[error(transparent)]
    Scenario(#[from] roam_world::ScenarioError),
}
