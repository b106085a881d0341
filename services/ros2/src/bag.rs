//! rosbag2 recordings: a directory with one MCAP file and `metadata.yaml`, as rosbag2's
//! MCAP storage plugin (`rosbag2_storage_mcap`) writes them, so `ros2 bag play`,
//! `ros2 bag info` and other rosbag2 readers open them.
//!
//! - The MCAP file has the profile `ros2`; each topic's schema is its type's full name
//!   (`nav_msgs/msg/OccupancyGrid`) with encoding `ros2msg` and the message definition
//!   of [`crate::types::message_definition`]; each channel has message encoding `cdr`
//!   and the metadata `offered_qos_profiles` (YAML) and `topic_type_hash` (RIHS01);
//!   messages are the CDR payloads sent on the wire, encapsulation header included.
//! - The metadata record `rosbag2` holds `serialized_metadata` (the bag's metadata as
//!   YAML) and `ROS_DISTRO`; `metadata.yaml` beside the file holds the same under
//!   `rosbag2_bagfile_information` (version 9, storage `mcap`).
//!
//! Uncompressed (no C build for zstd or lz4). The file is complete once [`Bag::finish`]
//! has run; until then a reader sees a truncated MCAP.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use crate::names::{Durability, Qos, Reliability};
use crate::{hash, types};

/// The rosbag2 metadata version written (Jazzy's).
pub const METADATA_VERSION: u32 = 9;
/// The ROS distribution the recording names (the one whose interfaces roam hashes).
pub const ROS_DISTRO: &str = "jazzy";

/// Why a recording failed.
#[derive(Debug, thiserror::Error)]
pub enum BagError {
    #[error("the rosbag2 directory {0} already exists and is not empty: give a new directory")]
    Exists(PathBuf),
    #[error("{path}: {reason}")]
    Io { path: PathBuf, reason: String },
    #[error("MCAP: {0}")]
    Mcap(String),
    #[error("no type description for '{0}'")]
    UnknownType(String),
}

#[derive(Debug)]
struct Topic {
    channel: u16,
    ros_type: &'static str,
    qos: Qos,
    hash: String,
    count: u64,
}

/// A recording in progress.
pub struct Bag {
    dir: PathBuf,
    file_name: String,
    writer: mcap::Writer<BufWriter<File>>,
    schemas: BTreeMap<&'static str, u16>,
    topics: BTreeMap<String, Topic>,
    first_ns: Option<u64>,
    last_ns: u64,
    count: u64,
}

impl std::fmt::Debug for Bag {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Bag")
            .field("dir", &self.dir)
            .field("count", &self.count)
            .finish_non_exhaustive()
    }
}

/// What a finished recording holds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BagSummary {
    pub dir: PathBuf,
    pub mcap: PathBuf,
    pub messages: u64,
    /// Topic name and message count.
    pub topics: Vec<(String, u64)>,
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> BagError + '_ {
    move |e| BagError::Io {
        path: path.to_owned(),
        reason: e.to_string(),
    }
}

fn mcap_error(e: mcap::McapError) -> BagError {
    BagError::Mcap(e.to_string())
}

/// An infinite rmw duration as rosbag2 writes it (`RMW_DURATION_INFINITE`).
const INFINITE: &str = "      sec: 9223372036\n      nsec: 854775807\n";

/// The `offered_qos_profiles` of one publisher, as rosbag2 (metadata version 9) writes
/// them: a YAML list with one profile, indented by `indent` spaces.
fn qos_yaml(qos: Qos, indent: usize) -> String {
    let pad = " ".repeat(indent);
    let reliability = match qos.reliability {
        Reliability::Reliable => "reliable",
        Reliability::BestEffort => "best_effort",
    };
    let durability = match qos.durability {
        Durability::TransientLocal => "transient_local",
        Durability::Volatile => "volatile",
    };
    let infinite: String = INFINITE.lines().map(|l| format!("{pad}{l}\n")).collect();
    format!(
        "{pad}- history: keep_last\n{pad}  depth: {}\n{pad}  reliability: {reliability}\n{pad}  durability: {durability}\n{pad}  deadline:\n{infinite}{pad}  lifespan:\n{infinite}{pad}  liveliness: automatic\n{pad}  liveliness_lease_duration:\n{infinite}{pad}  avoid_ros_namespace_conventions: false\n",
        qos.depth
    )
}

impl Bag {
    /// Starts a recording in `dir` (created; refused when it exists and is not empty).
    pub fn create(dir: &Path) -> Result<Bag, BagError> {
        if dir.exists() {
            let mut entries = std::fs::read_dir(dir).map_err(io(dir))?;
            if entries.next().is_some() {
                return Err(BagError::Exists(dir.to_owned()));
            }
        }
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        let stem = dir
            .file_name()
            .and_then(|n| n.to_str())
            .filter(|n| !n.is_empty())
            .unwrap_or("roam");
        let file_name = format!("{stem}_0.mcap");
        let path = dir.join(&file_name);
        let file = File::create(&path).map_err(io(&path))?;
        let writer = mcap::WriteOptions::new()
            .profile("ros2")
            .library(concat!("roam-ros2 ", env!("CARGO_PKG_VERSION")))
            .compression(None)
            .create(BufWriter::new(file))
            .map_err(mcap_error)?;
        Ok(Bag {
            dir: dir.to_owned(),
            file_name,
            writer,
            schemas: BTreeMap::new(),
            topics: BTreeMap::new(),
            first_ns: None,
            last_ns: 0,
            count: 0,
        })
    }

    fn channel(&mut self, topic: &str, ros_type: &'static str, qos: Qos) -> Result<u16, BagError> {
        if let Some(t) = self.topics.get(topic) {
            return Ok(t.channel);
        }
        let schema = match self.schemas.get(ros_type) {
            Some(&id) => id,
            None => {
                let definition = types::message_definition(ros_type)
                    .ok_or_else(|| BagError::UnknownType(ros_type.to_owned()))?;
                let id = self
                    .writer
                    .add_schema(ros_type, "ros2msg", definition.as_bytes())
                    .map_err(mcap_error)?;
                self.schemas.insert(ros_type, id);
                id
            }
        };
        let hash = hash::message_type_hash(ros_type)
            .map_err(|_| BagError::UnknownType(ros_type.to_owned()))?;
        let metadata = BTreeMap::from([
            ("offered_qos_profiles".to_owned(), qos_yaml(qos, 0)),
            ("topic_type_hash".to_owned(), hash.clone()),
        ]);
        let channel = self
            .writer
            .add_channel(schema, topic, "cdr", &metadata)
            .map_err(mcap_error)?;
        self.topics.insert(
            topic.to_owned(),
            Topic {
                channel,
                ros_type,
                qos,
                hash,
                count: 0,
            },
        );
        Ok(channel)
    }

    /// Records one message: `cdr` is the payload as sent (encapsulation header included),
    /// `time_ns` nanoseconds since the epoch.
    pub fn write(
        &mut self,
        topic: &str,
        ros_type: &'static str,
        qos: Qos,
        time_ns: u64,
        cdr: &[u8],
    ) -> Result<(), BagError> {
        let channel = self.channel(topic, ros_type, qos)?;
        let sequence = self.topics.get(topic).map_or(0, |t| t.count) as u32;
        self.writer
            .write_to_known_channel(
                &mcap::records::MessageHeader {
                    channel_id: channel,
                    sequence,
                    log_time: time_ns,
                    publish_time: time_ns,
                },
                cdr,
            )
            .map_err(mcap_error)?;
        if let Some(t) = self.topics.get_mut(topic) {
            t.count += 1;
        }
        self.first_ns = Some(self.first_ns.map_or(time_ns, |f| f.min(time_ns)));
        self.last_ns = self.last_ns.max(time_ns);
        self.count += 1;
        Ok(())
    }

    /// The bag's metadata (what `metadata.yaml` holds under `rosbag2_bagfile_information`),
    /// indented by `indent` spaces.
    fn metadata_yaml(&self, indent: usize) -> String {
        let pad = " ".repeat(indent);
        let start = self.first_ns.unwrap_or(0);
        let duration = self.last_ns.saturating_sub(start);
        let mut out = String::new();
        out.push_str(&format!("{pad}version: {METADATA_VERSION}\n"));
        out.push_str(&format!("{pad}storage_identifier: mcap\n"));
        out.push_str(&format!("{pad}duration:\n{pad}  nanoseconds: {duration}\n"));
        out.push_str(&format!(
            "{pad}starting_time:\n{pad}  nanoseconds_since_epoch: {start}\n"
        ));
        out.push_str(&format!("{pad}message_count: {}\n", self.count));
        out.push_str(&format!("{pad}topics_with_message_count:\n"));
        for (name, topic) in &self.topics {
            out.push_str(&format!("{pad}  - topic_metadata:\n"));
            out.push_str(&format!("{pad}      name: {name}\n"));
            out.push_str(&format!("{pad}      type: {}\n", topic.ros_type));
            out.push_str(&format!("{pad}      serialization_format: cdr\n"));
            out.push_str(&format!("{pad}      offered_qos_profiles:\n"));
            out.push_str(&qos_yaml(topic.qos, indent + 8));
            out.push_str(&format!(
                "{pad}      type_description_hash: {}\n",
                topic.hash
            ));
            out.push_str(&format!("{pad}    message_count: {}\n", topic.count));
        }
        out.push_str(&format!("{pad}compression_format: \"\"\n"));
        out.push_str(&format!("{pad}compression_mode: \"\"\n"));
        out.push_str(&format!(
            "{pad}relative_file_paths:\n{pad}  - {}\n",
            self.file_name
        ));
        out.push_str(&format!(
            "{pad}files:\n{pad}  - path: {}\n{pad}    starting_time:\n{pad}      nanoseconds_since_epoch: {start}\n{pad}    duration:\n{pad}      nanoseconds: {duration}\n{pad}    message_count: {}\n",
            self.file_name, self.count
        ));
        out.push_str(&format!("{pad}custom_data: ~\n"));
        out.push_str(&format!("{pad}ros_distro: {ROS_DISTRO}\n"));
        out
    }

    /// Writes the metadata record, the MCAP summary and `metadata.yaml`.
    pub fn finish(mut self) -> Result<BagSummary, BagError> {
        let serialized = self.metadata_yaml(0);
        self.writer
            .write_metadata(&mcap::records::Metadata {
                name: "rosbag2".to_owned(),
                metadata: BTreeMap::from([
                    ("serialized_metadata".to_owned(), serialized),
                    ("ROS_DISTRO".to_owned(), ROS_DISTRO.to_owned()),
                ]),
            })
            .map_err(mcap_error)?;
        self.writer.finish().map_err(mcap_error)?;
        let yaml = format!("rosbag2_bagfile_information:\n{}", self.metadata_yaml(2));
        let path = self.dir.join("metadata.yaml");
        std::fs::write(&path, yaml).map_err(io(&path))?;
        Ok(BagSummary {
            mcap: self.dir.join(&self.file_name),
            dir: self.dir.clone(),
            messages: self.count,
            topics: self
                .topics
                .iter()
                .map(|(name, t)| (name.clone(), t.count))
                .collect(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msg::{Path as RosPath, Time};

    #[test]
    fn a_recording_has_its_schema_channel_metadata_and_yaml() {
        let tmp = tempfile::tempdir().expect("tmp");
        let dir = tmp.path().join("run");
        let mut bag = Bag::create(&dir).expect("create");
        let path = crate::convert::path(&[[0.0, 0.0], [1.0, 1.0]], Time::default());
        let bytes = crate::cdr::encode(&path).expect("encode");
        for t in [10, 20] {
            bag.write("/r1/plan", types::PATH, Qos::LATCHED, t, &bytes)
                .expect("write");
        }
        let summary = bag.finish().expect("finish");
        assert_eq!(summary.messages, 2);
        assert_eq!(summary.topics, [("/r1/plan".to_owned(), 2)]);
        let yaml = std::fs::read_to_string(dir.join("metadata.yaml")).expect("yaml");
        assert!(yaml.contains("  - run_0.mcap\n"), "{yaml}");
        assert!(
            yaml.contains("type_description_hash: RIHS01_1957a5bb"),
            "{yaml}"
        );
        assert!(yaml.contains("nanoseconds: 10\n"), "{yaml}");
        let data = std::fs::read(&summary.mcap).expect("mcap");
        let mut seen = 0;
        for message in mcap::MessageStream::new(&data).expect("stream") {
            let message = message.expect("message");
            assert_eq!(message.channel.topic, "/r1/plan");
            assert_eq!(message.channel.message_encoding, "cdr");
            let schema = message.channel.schema.as_ref().expect("schema");
            assert_eq!(
                (schema.name.as_str(), schema.encoding.as_str()),
                (types::PATH, "ros2msg")
            );
            assert_eq!(
                crate::cdr::decode::<RosPath>(&message.data, "path", 1 << 20).expect("cdr"),
                path
            );
            seen += 1;
        }
        assert_eq!(seen, 2);
        // A second recording into the same directory is refused, not mixed in.
        assert!(matches!(Bag::create(&dir), Err(BagError::Exists(_))));
    }
}
