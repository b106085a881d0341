//! The service roles: map server, planner, router, and the whole stack in one process.

mod demo;
mod services;
mod stack;

pub(crate) use demo::{demo, site, DemoArgs};
pub(crate) use services::{
    controller, localization, map_server, mapper, mission, planner, ControllerArgs,
    LocalizationArgs, MapServerArgs, MapperArgs, MissionArgs, PlannerArgs,
};
pub(crate) use stack::{router, stack, RouterArgs, StackArgs};
