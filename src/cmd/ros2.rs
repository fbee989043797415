//! `situ ros2 FILE --map MAP [--msg-path DIR]… [--domain N] [--rmw cyclonedds|fastrtps]
//! [--duration S] [--record DIR] [--trust PUBKEY…]`: the ROS 2 bridge (docs/ros2.md), built with
//! `--features ros2`.

use super::{CliError, Outcome, FAILED, OK};
use std::path::PathBuf;

/// The RMW of the robot's ROS 2 nodes: how their services are carried.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Rmw {
    /// rmw_cyclonedds_cpp (Eclipse Cyclone DDS).
    Cyclonedds,
    /// rmw_fastrtps_cpp (eProsima Fast DDS, ROS 2's default).
    Fastrtps,
}

// The arguments of `situ ros2`.
#[derive(clap::Args)]
pub struct Args {
    /// The rules (a `.situ` source or a bundle).
    pub file: PathBuf,
    /// The ROS 2 map (TOML): which topic each event comes from, which agents are lifecycle nodes.
    #[arg(long)]
    pub map: PathBuf,
    /// A folder of ROS 2 message definitions, searched before the map's `msg_path`,
    /// AMENT_PREFIX_PATH and situ's own (repeatable): an install prefix (with `share/`), a
    /// folder of packages (`DIR/<pkg>/msg/*.msg`) or one package (`DIR/msg/*.msg`).
    #[arg(long, value_name = "DIR")]
    pub msg_path: Vec<PathBuf>,
    /// The DDS domain (default: ROS_DOMAIN_ID, else 0).
    #[arg(long)]
    pub domain: Option<u16>,
    /// The RMW of the robot's nodes: how their lifecycle services are carried.
    #[arg(long, value_enum, default_value_t = Rmw::Fastrtps)]
    pub rmw: Rmw,
    /// Stop after this many seconds (default: until Ctrl-C or SIGTERM).
    #[arg(long)]
    pub duration: Option<f64>,
    /// Record what came and went as a ROS 2 bag (a new directory; MCAP storage).
    #[arg(long, value_name = "DIR")]
    pub record: Option<PathBuf>,
    #[command(flatten)]
    pub trust: super::Trust,
}

const NO_BRIDGE: &str = "this situ was built without the ROS 2 bridge: `cargo build --features ros2` \
                         (or `cargo install --path . --features ros2`)";

#[cfg(not(feature = "ros2"))]
pub fn run(args: Args) -> Outcome {
    let _ = (
        &args.file,
        &args.map,
        &args.msg_path,
        args.domain,
        args.rmw,
        args.duration,
        &args.record,
        &args.trust.trust,
        OK,
        FAILED,
    );
    Err(CliError::Usage(NO_BRIDGE.into()))
}

/// The domain: `--domain`, else `ROS_DOMAIN_ID`, else 0.
#[cfg(feature = "ros2")]
fn domain(flag: Option<u16>) -> Result<u16, String> {
    if let Some(d) = flag {
        return Ok(d);
    }
    match std::env::var("ROS_DOMAIN_ID") {
        Err(_) => Ok(0),
        Ok(v) if v.trim().is_empty() => Ok(0),
        Ok(v) => v
            .trim()
            .parse::<u16>()
            .ok()
            .filter(|&d| d <= 232)
            .ok_or_else(|| format!("ROS_DOMAIN_ID is `{v}`: a domain is a whole number from 0 to 232")),
    }
}

#[cfg(feature = "ros2")]
pub fn run(args: Args) -> Outcome {
    use situ_bridge_ros2::core::{Core, SetupError};
    use situ_bridge_ros2::dds::{self, Options};
    use situ_compiler::loader::{read_bounded, MAX_FILE_BYTES};
    use situ_compiler::render;
    use situ_compiler::source::{SourceFile, SourceMap};
    use std::time::Duration;

    let _ = NO_BRIDGE;
    let domain = domain(args.domain).map_err(CliError::Usage)?;
    let duration = match args.duration {
        None => None,
        Some(s) if s.is_finite() && s > 0.0 && s <= 1e7 => Some(Duration::from_secs_f64(s)),
        Some(s) => {
            return Err(CliError::Usage(format!("--duration {s}: give a number of seconds above 0")));
        }
    };
    super::check::msg_path_folders(&args.msg_path)?;
    let trust = args.trust.policy()?;
    let program = super::program::load(&args.file, false, &trust).map_err(CliError::Reported)?;
    let text = match read_bounded(&args.map, MAX_FILE_BYTES, "a map")
        .and_then(|b| String::from_utf8(b).map_err(|_| std::io::Error::other("the map is not UTF-8 text")))
    {
        Ok(t) => t,
        Err(e) => {
            return Err(CliError::Usage(format!("{}: {e}", args.map.display())));
        }
    };
    // A bundle has no source: the map is read against its agents and events.
    let (mut sources, model) = match program.checked {
        Some(checked) => (checked.sources, checked.model),
        None => {
            let mut sources = SourceMap::new();
            let name = format!("{} (a bundle: no source)", args.file.display());
            let file = sources.add(SourceFile::new(name, ""));
            (sources, situ_ros2_map::skeleton::model_of(&program.content, file))
        }
    };
    let file = sources.add(SourceFile::new(args.map.display().to_string(), text));
    let map_text = sources.get(file).text.clone();
    let map_dir = args.map.parent().unwrap_or(std::path::Path::new(""));
    let (msgs, found) = match situ_ros2_map::map::parse(&map_text, file) {
        Ok(parsed) => situ_ros2_map::load::registry_of(&parsed, map_dir, &args.msg_path, file),
        // Core::new reports the map that does not parse.
        Err(_) => (situ_ros2_map::Registry::carried(), Vec::new()),
    };
    let core = match Core::new(program.content, &model, &map_text, &msgs, file) {
        Ok(core) if found.is_empty() => core,
        result => {
            let mut found = found;
            if let Err(SetupError::Map(more)) = result {
                found.extend(more);
            }
            print!("{}", render::human_list(&sources, &found, super::style()));
            return Err(CliError::Failed(format!(
                "`{}` has errors; `situ check RULES --ros2-map {}` explains each",
                args.map.display(),
                args.map.display()
            )));
        }
    };
    if !core.map_warnings().is_empty() {
        eprint!("{}", render::human_list(&sources, core.map_warnings(), super::style()));
    }
    let rmw = match args.rmw {
        Rmw::Cyclonedds => dds::Rmw::CycloneDds,
        Rmw::Fastrtps => dds::Rmw::FastRtps,
    };
    let topics: Vec<String> = core.topics().into_iter().map(|(t, _)| t).collect();
    let nodes: Vec<String> = core.nodes().iter().map(|n| n.name.clone()).collect();
    eprintln!(
        "situ ros2: domain {domain}, reading {}; driving {} (the RMW's services: {:?}); publishing /situ/state, /situ/agents, /diagnostics",
        if topics.is_empty() { "no topic".to_string() } else { topics.join(", ") },
        if nodes.is_empty() { "no lifecycle node".to_string() } else { nodes.join(", ") },
        args.rmw,
    );
    let bag = match &args.record {
        None => None,
        Some(dir) => match situ_bridge_ros2::bag::Bag::create(dir, &msgs) {
            Ok(bag) => Some(bag),
            Err(e) => {
                return Err(CliError::Usage(format!(
                    "--record {}: {e} (a bag is a new directory; it is never written over)",
                    dir.display()
                )));
            }
        },
    };
    let options =
        Options { domain, rmw, heartbeat: Duration::from_millis(10), duration, stop: super::distributed::stop_flag() };
    match dds::run(core, &options, bag) {
        Ok(report) => {
            let c = report.counters;
            let mut lat = report.latencies.clone();
            lat.sort_unstable();
            let pct =
                |p: f64| lat.get(((lat.len() as f64 - 1.0) * p).round() as usize).map_or(0.0, |&ns| ns as f64 / 1e3);
            eprintln!(
                "situ ros2: ended in {}; {} messages ({:.0}/s), {} refused, {} events, {} rejected, {} state changes, {} lifecycle requests, {} failures",
                report.state, c.messages, report.rate, c.refused, c.events, c.rejected, c.changes, c.requests, c.failures
            );
            if report.own_ignored > 0 {
                eprintln!(
                    "situ ros2: {} messages of its own writers ignored (the map reads a topic the bridge publishes)",
                    report.own_ignored
                );
            }
            if let Some(e) = &report.record_error {
                eprintln!("error: the recording stopped: {e}");
            } else if let Some(dir) = &args.record {
                eprintln!("situ ros2: recorded {} (a ROS 2 bag, MCAP storage)", dir.display());
            }
            if !lat.is_empty() {
                eprintln!(
                    "situ ros2: message to first lifecycle request: p50 {:.0} µs, p99 {:.0} µs, max {:.0} µs ({} times)",
                    pct(0.5),
                    pct(0.99),
                    pct(1.0),
                    lat.len()
                );
            }
            Ok(if report.record_error.is_some() { FAILED } else { OK })
        }
        Err(e) => Err(CliError::Usage(format!("DDS: {e}"))),
    }
}
