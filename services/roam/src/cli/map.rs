//! `roam map`: map files offline, and the layers of a running map server.

use std::path::PathBuf;

use clap::Subcommand;
use roam_proto::keys;
use roam_proto::map::{LayerList, LoadMap};
use roam_world::ros_map;

use super::client::{connect, ClientArgs};

#[derive(Debug, Subcommand)]
pub(crate) enum MapCommand {
    /// Read a ROS map.yaml without any network and print its size and cell counts.
    Inspect {
        map: PathBuf,
        /// Print JSON: {"width","height","resolution","origin","occupied","free","unknown"}.
        #[arg(long)]
        json: bool,
    },
    /// List the layers of a running map server.
    Layers(ClientArgs),
    /// Ask a running map server to load a map file from its own file system.
    Load {
        path: String,
        #[command(flatten)]
        client: ClientArgs,
    },
}

pub(crate) async fn map(command: MapCommand) -> anyhow::Result<()> {
    match command {
        MapCommand::Inspect { map, json } => {
            let loaded = ros_map::load(&map, roam_world::DEFAULT_MAX_CELLS)?;
            let counts = ros_map::count_cells(&loaded.grid);
            let meta = loaded.grid.meta;
            let value = serde_json::json!({
                "width": meta.width,
                "height": meta.height,
                "resolution": meta.resolution,
                "origin": [meta.origin.x, meta.origin.y, meta.origin.yaw],
                "occupied": counts.occupied,
                "free": counts.free,
                "unknown": counts.unknown,
            });
            if json {
                println!("{value}");
            } else {
                println!(
                    "{}: {}x{} cells at {} m/cell, origin ({}, {}, {}), mode {}\n  occupied {}  free {}  unknown {}",
                    map.display(),
                    meta.width,
                    meta.height,
                    meta.resolution,
                    meta.origin.x,
                    meta.origin.y,
                    meta.origin.yaw,
                    loaded.params.mode.as_str(),
                    counts.occupied,
                    counts.free,
                    counts.unknown
                );
            }
            Ok(())
        }
        MapCommand::Layers(client) => {
            let (requester, session) = connect(&client).await?;
            let list: Result<LayerList, _> = requester
                .request::<LayerList, LayerList>(&keys::map_index(&client.root), None)
                .await;
            let _ = session.close().await;
            println!("{}", serde_json::to_string_pretty(&list?)?);
            Ok(())
        }
        MapCommand::Load { path, client } => {
            let (requester, session) = connect(&client).await?;
            let request = LoadMap {
                path,
                base_version: None,
            };
            let list: Result<LayerList, _> = requester
                .request(&keys::map_load(&client.root), Some(&request))
                .await;
            let _ = session.close().await;
            println!("{}", serde_json::to_string_pretty(&list?)?);
            Ok(())
        }
    }
}
