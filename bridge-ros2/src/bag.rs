//! The bridge's recording: a ROS 2 bag (rosbag2, MCAP storage) that
//! `ros2 bag`, the `rosbags` Python package and Foxglove open. A directory
//! with `metadata.yaml` and one `.mcap` file of profile `ros2`: every
//! message the bridge read (its CDR bytes as they came) and everything it
//! published (`/situ/state`, `/situ/agents`, `/diagnostics`), each channel
//! with its type's `.msg` definition (`ros2msg`, the text the map's
//! definitions were loaded from).
//!
//! The MCAP file is kept readable at every flush (once a second at most,
//! [`situ_runtime::record::mcap::staged`]): a bridge killed mid-run leaves
//! a bag that reads up to its last second. `metadata.yaml` follows: it is
//! written when a topic is added, at every flush with the counts then on
//! disk, and at the end; each time whole (written aside, then renamed).

use serde::Serialize;
use situ_ros2_map::Registry;
use situ_runtime::record::mcap::staged::Staged;
use std::collections::BTreeMap;
use std::fs::{self, File};
use std::io;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// How often the file is flushed at most while messages come.
const FLUSH_EVERY: Duration = Duration::from_secs(1);

struct Channel {
    id: u16,
    ty: String,
    count: u64,
}

pub struct Bag {
    dir: PathBuf,
    file_name: String,
    writer: Option<mcap::Writer<Staged>>,
    finishing: std::sync::Arc<std::sync::atomic::AtomicBool>,
    channels: BTreeMap<String, Channel>,
    schemas: BTreeMap<String, u16>,
    msgs: Registry,
    first: Option<u64>,
    last: u64,
    sequence: u32,
    last_flush: Instant,
}

fn mcap_err(e: mcap::McapError) -> io::Error {
    io::Error::other(e.to_string())
}

/// The `ros2msg` schema of `full` as rosbag2 writes it (see
/// [`Registry::schema`]): from `msgs`, else from the definitions situ
/// carries (the types the bridge publishes itself).
pub fn ros2msg(msgs: &Registry, full: &str) -> Option<String> {
    msgs.schema(full).or_else(|| Registry::carried().schema(full))
}

impl Bag {
    /// A new bag in `dir`, which must not exist yet (a bag is never
    /// written over); its schemas are the definitions of `msgs`.
    pub fn create(dir: &Path, msgs: &Registry) -> io::Result<Bag> {
        fs::create_dir(dir)?;
        let stem = dir.file_name().and_then(|n| n.to_str()).unwrap_or("situ").to_string();
        let file_name = format!("{stem}_0.mcap");
        let (file, finishing) = Staged::new(File::create(dir.join(&file_name))?);
        let mut writer = mcap::WriteOptions::new()
            .profile("ros2")
            .library(format!("situ {}", env!("CARGO_PKG_VERSION")))
            .compression(None)
            .disable_seeking(true)
            .create(file)
            .map_err(mcap_err)?;
        writer.flush().map_err(mcap_err)?;
        let bag = Bag {
            dir: dir.to_path_buf(),
            file_name,
            writer: Some(writer),
            finishing,
            channels: BTreeMap::new(),
            schemas: BTreeMap::new(),
            msgs: msgs.clone(),
            first: None,
            last: 0,
            sequence: 0,
            last_flush: Instant::now(),
        };
        bag.write_metadata()?;
        Ok(bag)
    }

    /// Adds a topic of type `ty` (a full name the bag's registry defines).
    pub fn add_topic(&mut self, topic: &str, ty: &str) -> io::Result<()> {
        if self.channels.contains_key(topic) {
            return Ok(());
        }
        let w = self.writer.as_mut().ok_or_else(|| io::Error::other("the bag is finished"))?;
        let schema = match self.schemas.get(ty) {
            Some(&id) => id,
            None => {
                let text =
                    ros2msg(&self.msgs, ty).ok_or_else(|| io::Error::other(format!("no definition of `{ty}`")))?;
                let id = w.add_schema(ty, "ros2msg", text.as_bytes()).map_err(mcap_err)?;
                self.schemas.insert(ty.to_string(), id);
                id
            }
        };
        let id = w.add_channel(schema, topic, "cdr", &BTreeMap::new()).map_err(mcap_err)?;
        self.channels.insert(topic.to_string(), Channel { id, ty: ty.to_string(), count: 0 });
        // A bag cut short still names its topics.
        w.flush().map_err(mcap_err)?;
        self.write_metadata()
    }

    /// One message of `topic` at `time` (ns since the Unix epoch): its CDR
    /// bytes, encapsulation header included.
    pub fn write(&mut self, topic: &str, time: u64, cdr: &[u8]) -> io::Result<()> {
        let Some(channel) = self.channels.get_mut(topic) else {
            return Err(io::Error::other(format!("`{topic}` is not a topic of the bag")));
        };
        let w = self.writer.as_mut().ok_or_else(|| io::Error::other("the bag is finished"))?;
        self.sequence = self.sequence.wrapping_add(1);
        let header = mcap::records::MessageHeader {
            channel_id: channel.id,
            sequence: self.sequence,
            log_time: time,
            publish_time: time,
        };
        w.write_to_known_channel(&header, cdr).map_err(mcap_err)?;
        channel.count += 1;
        self.first.get_or_insert(time);
        self.last = self.last.max(time);
        self.flush_if_due()
    }

    /// Flushes when a second has passed since the last flush: what was
    /// recorded until now survives the process (the bridge calls it on
    /// every tick too, so a quiet second is flushed as well).
    pub fn flush_if_due(&mut self) -> io::Result<()> {
        if self.last_flush.elapsed() >= FLUSH_EVERY {
            self.last_flush = Instant::now();
            if let Some(w) = self.writer.as_mut() {
                w.flush().map_err(mcap_err)?;
                // The counts of what is now on disk.
                self.write_metadata()?;
            }
        }
        Ok(())
    }

    /// A message the bridge publishes, serialized as ROS 2 does (CDR, little endian).
    pub fn write_serde<T: Serialize>(&mut self, topic: &str, time: u64, msg: &T) -> io::Result<()> {
        let bytes = crate::msgs::to_cdr(msg).map_err(io::Error::other)?;
        self.write(topic, time, &bytes)
    }

    /// Closes the MCAP file with its summary and writes the final metadata.
    pub fn finish(&mut self) -> io::Result<PathBuf> {
        if let Some(mut w) = self.writer.take() {
            self.finishing.store(true, std::sync::atomic::Ordering::SeqCst);
            w.finish().map_err(mcap_err)?;
        }
        self.write_metadata()?;
        Ok(self.dir.clone())
    }

    /// `metadata.yaml`, as rosbag2 writes it (version 5).
    fn write_metadata(&self) -> io::Result<()> {
        let start = self.first.unwrap_or(0);
        let duration = self.last.saturating_sub(start);
        let total: u64 = self.channels.values().map(|c| c.count).sum();
        let mut topics = String::new();
        for (name, c) in &self.channels {
            topics.push_str(&format!(
                "    - topic_metadata:\n        name: {name}\n        type: {}\n        serialization_format: cdr\n        offered_qos_profiles: \"\"\n        type_description_hash: \"\"\n      message_count: {}\n",
                c.ty, c.count
            ));
        }
        if topics.is_empty() {
            topics.push_str("    []\n");
        }
        let text = format!(
            "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n  duration:\n    nanoseconds: {duration}\n  starting_time:\n    nanoseconds_since_epoch: {start}\n  message_count: {total}\n  topics_with_message_count:\n{topics}  compression_format: \"\"\n  compression_mode: \"\"\n  relative_file_paths:\n    - {}\n  files:\n    - path: {}\n      starting_time:\n        nanoseconds_since_epoch: {start}\n      duration:\n        nanoseconds: {duration}\n      message_count: {total}\n",
            self.file_name, self.file_name
        );
        let aside = self.dir.join(".metadata.yaml.part");
        fs::write(&aside, text)?;
        fs::rename(&aside, self.dir.join("metadata.yaml"))
    }
}

impl Drop for Bag {
    fn drop(&mut self) {
        if self.writer.is_some() {
            let _ = self.finish();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn definitions_carry_their_dependencies_once() {
        let msgs = Registry::carried();
        let scan = ros2msg(&msgs, "sensor_msgs/msg/LaserScan").unwrap();
        assert!(scan.starts_with("# Single scan from a planar laser range-finder\n"), "{scan}");
        assert!(scan.contains("\nstd_msgs/Header header "), "{scan}");
        assert_eq!(scan.matches("MSG: std_msgs/msg/Header").count(), 1);
        assert_eq!(scan.matches("MSG: builtin_interfaces/msg/Time").count(), 1);
        let diag = ros2msg(&msgs, "diagnostic_msgs/msg/DiagnosticArray").unwrap();
        // `DiagnosticStatus` and `KeyValue` are named without their package.
        assert!(diag.contains("MSG: diagnostic_msgs/msg/DiagnosticStatus\n"), "{diag}");
        assert!(diag.contains("MSG: diagnostic_msgs/msg/KeyValue\n"), "{diag}");
        assert!(diag.contains("byte ERROR=2"), "the constants are in the schema: {diag}");
        assert!(ros2msg(&msgs, "std_msgs/msg/String").unwrap().ends_with("\nstring data\n"));
        assert_eq!(ros2msg(&msgs, "nope/msg/Nope"), None);
    }

    #[test]
    fn a_bag_is_never_written_over() {
        let dir = std::env::temp_dir().join(format!("situ-bag-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        let mut bag = Bag::create(&dir, &Registry::carried()).unwrap();
        bag.add_topic("/situ/state", "std_msgs/msg/String").unwrap();
        bag.write("/situ/state", 5, &[0, 1, 0, 0, 2, 0, 0, 0, b'A', 0]).unwrap();
        assert!(bag.write("/nope", 6, &[]).is_err());
        bag.finish().unwrap();
        let meta = fs::read_to_string(dir.join("metadata.yaml")).unwrap();
        assert!(meta.contains("message_count: 1") && meta.contains("name: /situ/state"), "{meta}");
        assert!(Bag::create(&dir, &Registry::carried()).is_err());
        fs::remove_dir_all(&dir).unwrap();
    }
}
