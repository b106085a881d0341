//! The flags every service subcommand shares (its config file, key root, instance name
//! and Zenoh session), and running a role with them.

use std::path::PathBuf;

use clap::Args;
use roam_runtime::SessionArgs;
use roam_stack::{Role, RoleConfig};

#[derive(Debug, Args)]
pub(crate) struct ServiceArgs {
    /// The service's YAML config file.
    #[arg(long, value_name = "FILE")]
    pub(crate) config: Option<PathBuf>,
    /// Key root for every key expression.
    #[arg(long, env = "ROAM_ROOT")]
    pub(crate) root: Option<String>,
    /// Instance name in the liveliness token (default: the Zenoh session id).
    #[arg(long)]
    pub(crate) instance: Option<String>,
    #[command(flatten)]
    pub(crate) session: SessionArgs,
}

impl ServiceArgs {
    /// The role's config: its file (or the defaults), then `--root` and `--instance`.
    pub(crate) fn load_config<T: RoleConfig>(&self) -> anyhow::Result<T> {
        let mut config: T = match &self.config {
            Some(path) => roam_runtime::config_file::load(path)?,
            None => T::default(),
        };
        if let Some(root) = &self.root {
            *config.root_mut() = root.clone();
        }
        if let Some(instance) = &self.instance {
            *config.instance_mut() = Some(instance.clone());
        }
        Ok(config)
    }

    /// Runs `role` until SIGINT or SIGTERM, on the Zenoh config of its file section,
    /// `ZENOH_CONFIG`, then the flags.
    pub(crate) async fn run(&self, role: Role) -> anyhow::Result<()> {
        let zenoh = self.session.zenoh_config(role.zenoh())?;
        role.run(zenoh, roam_runtime::signals::cancel_on_signal())
            .await
            .map_err(anyhow::Error::msg)
    }
}
