//! The scenarios, as functions that run one and return what was measured:
//! the tests of tests/faults.rs run them briefly and assert on events; the
//! soak tests (`--ignored`) run them longer and print the figures.

use super::lab::Lab;
use super::stack::*;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::{Duration, Instant};

pub const LONG: Duration = Duration::from_secs(60);

/// Waits until the observer has seen `n` statuses after `after_ns`, or
/// the board's process has ended (its rules reached a final state).
fn wait_statuses(lab: &mut Lab, running: &Running, after_ns: u64, n: usize) {
    let observer = running.observer.expect("an observer");
    let end = Instant::now() + LONG;
    while seen(lab, observer).iter().filter(|s| s.at_ns > after_ns).count() < n {
        if lab.wait(running.procs["board"], Duration::ZERO).is_some() {
            std::thread::sleep(Duration::from_secs(1));
            return;
        }
        if Instant::now() >= end {
            panic!("fewer than {n} statuses reached the observer within {LONG:?}\n{}", lab.outputs());
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// What a partition of the pipeline's host did.
#[derive(Debug)]
pub struct Partition {
    pub cut_ns: u64,
    pub healed_ns: u64,
    /// The pipeline host's time without status across the heal (ms).
    pub gap_ms: f64,
    /// From the heal to the first status there (ms).
    pub back_after_ms: f64,
    /// The pipeline's safe-mode periods (ns).
    pub safe: Vec<(u64, Option<u64>)>,
    /// The sensors' (their host was not cut).
    pub sensors_safe: Vec<(u64, Option<u64>)>,
    pub board_out: String,
    pub pipeline_out: String,
    /// The states the board's recording went through before the
    /// stop, and the path the pipeline followed.
    pub board_states: Vec<String>,
    pub pipeline_path: Vec<String>,
}

/// Fig. 5 on three hosts; once every process follows RO, the pipeline's
/// host is cut off from the switch for `cut`, then joined again; the run
/// goes on until the observer on that host has had 5 statuses after the
/// heal.
pub fn partition_pipeline(cut: Duration) -> Partition {
    let mut lab = Lab::new(&["board", "sensors", "pipeline"]);
    let procs = fig5_peers();
    let deploy = write_deployment(&lab, "fig5", &procs, None);
    let mut running = start(&mut lab, &fig5_rules(), &deploy, &procs);
    let at = format!("tcp/{}:7449", lab.addr("pipeline"));
    running.observer = Some(observe(&mut lab, "pipeline", &at, "client", "fig5"));
    for p in ["board", "sensors", "pipeline"] {
        wait_state(&mut lab, &running, p, "RO", LONG);
    }
    std::thread::sleep(Duration::from_millis(500));
    let cut_ns = now_ns();
    lab.partition("pipeline");
    std::thread::sleep(cut);
    let healed_ns = now_ns();
    lab.heal("pipeline");
    wait_statuses(&mut lab, &running, healed_ns, 5);
    let stopped = stop_all(&mut lab, &running);
    let seen = seen(&lab, running.observer.unwrap());
    check_monotonic(&seen).unwrap();
    // Nothing arrives while the host is cut off (a status on its way at
    // the cut may arrive just after it): the time without status is the
    // one across the heal.
    let (gap_ms, back) = gap_across(&seen, healed_ns).expect("statuses before the heal and after it");
    Partition {
        cut_ns,
        healed_ns,
        gap_ms,
        back_after_ms: back.saturating_sub(healed_ns) as f64 / 1e6,
        safe: safe_mode_periods(&recording(&lab, "pipeline"), stopped),
        sensors_safe: safe_mode_periods(&recording(&lab, "sensors"), stopped),
        board_out: lab.stdout(running.procs["board"]),
        pipeline_out: lab.stdout(running.procs["pipeline"]),
        board_states: recorded_states(&recording(&lab, "board"), stopped),
        pipeline_path: path(&lab.stdout(running.procs["pipeline"])),
    }
}

/// What a router's restart did.
#[derive(Debug)]
pub struct RouterRestart {
    pub killed_ns: u64,
    /// The pipeline host's time without status across the restart (ms);
    /// `None`: no status came after it (the board stopped at a final state
    /// before the router was back).
    pub gap_ms: Option<f64>,
    /// From the new router's start to the first status (ms).
    pub back_after_ms: Option<f64>,
    pub safe: Vec<(u64, Option<u64>)>,
    pub board_out: String,
    pub pipeline_out: String,
    /// The states the board's recording went through before the
    /// stop, and the path the pipeline followed.
    pub board_states: Vec<String>,
    pub pipeline_path: Vec<String>,
    /// With two boards: the statuses' epochs and boards as the observer
    /// saw them change (the first status's, then each change), and
    /// those that came in the last second before the stop.
    pub epochs: Vec<(Option<u64>, Option<String>)>,
    pub last_second: Vec<(Option<u64>, Option<String>)>,
    /// With two boards: the standby's recorded states.
    pub standby_states: Vec<String>,
    /// Every process's standard error (what the boards said: who led).
    pub errs: String,
}

/// The changes of (epoch, board) in the statuses seen, in order.
pub fn epoch_changes(seen: &[Seen]) -> Vec<(Option<u64>, Option<String>)> {
    let mut out: Vec<(Option<u64>, Option<String>)> = Vec::new();
    for s in seen {
        let k = (s.epoch, s.board.clone());
        if out.last() != Some(&k) {
            out.push(k);
        }
    }
    out
}

/// The distinct (epoch, board) of the statuses that arrived in `from..to`.
fn epochs_within(seen: &[Seen], from: u64, to: u64) -> Vec<(Option<u64>, Option<String>)> {
    epoch_changes(&seen.iter().filter(|s| s.at_ns > from && s.at_ns <= to).cloned().collect::<Vec<_>>())
}

/// Every process's standard error, named.
fn errs(lab: &Lab, running: &Running) -> String {
    running.procs.iter().map(|(n, pid)| format!("--- {n}:\n{}", lab.stderr(*pid))).collect()
}

/// Fig. 5's processes as clients of a router process, each on its own host
/// (the sensors' `stale after` is `stale`, `fig5_rules_with_stale`, or the
/// file's 500 ms); once every process follows RO, the router is killed
/// (SIGKILL) and started again after `down`; the run goes on until the
/// observer (a client of the router, on the pipeline's host) has had 5
/// statuses after the restart.
///
/// With `two_boards`, a second board process, `standby`, on a host of its
/// own, is a client of the router too: the router's restart cuts the
/// boards from each other as well as from the agents.
pub fn restart_router(down: Duration, stale: Option<&str>, two_boards: bool) -> RouterRestart {
    let hosts: &[&str] = if two_boards {
        &["router", "board", "standby", "sensors", "pipeline"]
    } else {
        &["router", "board", "sensors", "pipeline"]
    };
    let mut lab = Lab::new(hosts);
    let procs = if two_boards { super::standby::fig5_router_two_boards() } else { fig5_router() };
    let rules = match stale {
        Some(stale) => fig5_rules_with_stale(&lab, stale),
        None => fig5_rules(),
    };
    let deploy = write_deployment(&lab, "fig5", &procs, None);
    let mut running = start(&mut lab, &rules, &deploy, &procs);
    let at = format!("tcp/{}:7447", lab.addr("router"));
    running.observer = Some(observe(&mut lab, "pipeline", &at, "client", "fig5"));
    for p in ["sensors", "pipeline"] {
        wait_state(&mut lab, &running, p, "RO", LONG);
    }
    std::thread::sleep(Duration::from_millis(500));
    let killed_ns = now_ns();
    lab.kill9(running.procs["router"]);
    std::thread::sleep(down);
    let restarted_ns = now_ns();
    let again = lab.spawn("router", "router-again", situ_run(&lab, &rules, &deploy, "router"));
    running.procs.insert("router".into(), again);
    wait_statuses(&mut lab, &running, restarted_ns, 5);
    if two_boards {
        // Time for the boards to hear each other again and the lower
        // epoch to step down (what the last second then shows).
        std::thread::sleep(Duration::from_secs(2));
    }
    let stopped = stop_all(&mut lab, &running);
    let seen = seen(&lab, running.observer.unwrap());
    if two_boards {
        // Both boards may lead while the router is down: once it is back,
        // the old leader's last statuses may reach the observer after the
        // new leader's (agents ignore them, a lower epoch). Within an
        // epoch, `seq` never goes back.
        for epoch in epoch_changes(&seen).iter().map(|e| e.0) {
            let one: Vec<Seen> = seen.iter().filter(|s| s.epoch == epoch).cloned().collect();
            check_monotonic(&one).unwrap();
        }
    } else {
        check_monotonic(&seen).unwrap();
    }
    // Nothing arrives while no router runs (a status on its way at the
    // kill may arrive just after it): the time without status is the one
    // across the restart.
    let across = gap_across(&seen, restarted_ns);
    RouterRestart {
        killed_ns,
        gap_ms: across.map(|a| a.0),
        back_after_ms: across.map(|a| a.1.saturating_sub(restarted_ns) as f64 / 1e6),
        safe: safe_mode_periods(&recording(&lab, "pipeline"), stopped),
        board_out: lab.stdout(running.procs["board"]),
        pipeline_out: lab.stdout(running.procs["pipeline"]),
        board_states: recorded_states(&recording(&lab, "board"), stopped),
        pipeline_path: path(&lab.stdout(running.procs["pipeline"])),
        epochs: epoch_changes(&seen),
        last_second: epochs_within(&seen, stopped.saturating_sub(1_000_000_000), stopped),
        standby_states: if two_boards { recorded_states(&recording(&lab, "standby"), stopped) } else { Vec::new() },
        errs: errs(&lab, &running),
    }
}

/// What delay and loss between the hosts did.
#[derive(Debug)]
pub struct Lossy {
    pub from_ns: u64,
    pub to_ns: u64,
    /// Gaps between statuses on the pipeline's host while the loss lasted (ms).
    pub gaps_ms: Vec<f64>,
    pub statuses: usize,
    /// The pipeline's safe-mode periods (ns).
    pub safe: Vec<(u64, Option<u64>)>,
    /// Arrival times of the statuses the observer saw (ns).
    pub arrivals: Vec<u64>,
    /// The change of the hosts' TCP counters (summed over the hosts) while
    /// the loss lasted.
    pub tcp: BTreeMap<String, u64>,
    pub board_out: String,
    /// The states the board's recording went through before the
    /// stop, and the path the pipeline followed.
    pub board_states: Vec<String>,
    pub pipeline_path: Vec<String>,
    /// The (epoch, board) of the statuses seen, as they changed over the
    /// whole run (one entry: one leader throughout).
    pub epochs: Vec<(Option<u64>, Option<String>)>,
    /// The boards' lines on leading and stepping down (standard error).
    pub leadership: Vec<String>,
    /// The boards' closing lines on the beats they heard over UDP
    /// (standard error), each prefixed with its process.
    pub beats: Vec<String>,
    /// Whether the statuses seen never went back ([`check_monotonic`]):
    /// after a false takeover the old leader's last statuses may reach the
    /// observer after the new one's (agents ignore them, a lower epoch).
    pub monotonic: Result<(), String>,
}

/// The settings of [`delay_and_loss`].
#[derive(Debug, Clone)]
pub struct LossySettings {
    pub delay_ms: u32,
    pub loss_percent: u8,
    pub lasting: Duration,
    /// The route's `rto_min` in every host (ms), Linux's 200 ms if `None`.
    pub rto_min_ms: Option<u32>,
    /// The rules: examples/fig5 with this `stale after` for the sensors
    /// (`None`: the file's 500 ms).
    pub stale: Option<&'static str>,
    /// A second board, `standby`, on a host of its own: a standby group
    /// whose boards talk through the relay too.
    pub two_boards: bool,
    /// The boards also beat over UDP (`beats` in the deployment), through
    /// the relay's datagram routes and the same loss.
    pub beats: bool,
}

/// The TCP counters of the hosts and the switch (the relay), summed.
fn tcp_total(lab: &Lab, hosts: &[&str]) -> BTreeMap<String, u64> {
    let mut sum = BTreeMap::new();
    for counters in hosts.iter().map(|h| lab.tcp_counters(h)).chain([lab.switch_tcp_counters()]) {
        for (k, v) in counters {
            *sum.entry(k).or_insert(0) += v;
        }
    }
    sum
}

/// Fig. 5 on three hosts whose every link crosses a relay that delays
/// each way by `delay_ms`; once every process follows RO, each host drops
/// `loss_percent` % of what it sends to the others, for `lasting`.
///
/// With `two_boards` ([`super::standby::fig5_two_boards`]) the boards' log,
/// acknowledgements and beats cross the relay and the loss as well: a
/// follower that misses the leader's beats for its lease would lead (a
/// false takeover), which [`Lossy::epochs`] shows.
pub fn delay_and_loss(s: &LossySettings) -> Lossy {
    let hosts: &[&str] =
        if s.two_boards { &["board", "standby", "sensors", "pipeline"] } else { &["board", "sensors", "pipeline"] };
    let mut lab = Lab::new(hosts);
    let procs = if s.two_boards { super::standby::fig5_two_boards() } else { fig5_peers() };
    let udp = if s.beats { beat_targets(&procs) } else { Vec::new() };
    let relay = lab.relay(s.delay_ms, &relay_targets(&procs), &udp);
    for &h in hosts {
        lab.only_through_switch(h);
    }
    if let Some(ms) = s.rto_min_ms {
        lab.rto_min(ms);
    }
    let rules: PathBuf = match s.stale {
        Some(stale) => fig5_rules_with_stale(&lab, stale),
        None => fig5_rules(),
    };
    let deploy = if s.beats {
        write_deployment_with_beats(&lab, "fig5", &procs, Some(&relay))
    } else {
        write_deployment(&lab, "fig5", &procs, Some(&relay))
    };
    let mut running = start(&mut lab, &rules, &deploy, &procs);
    let at = format!("tcp/{}:7449", lab.addr("pipeline"));
    running.observer = Some(observe(&mut lab, "pipeline", &at, "client", "fig5"));
    for p in ["sensors", "pipeline"] {
        wait_state(&mut lab, &running, p, "RO", LONG);
    }
    let before = tcp_total(&lab, hosts);
    let from_ns = now_ns();
    for &h in hosts {
        lab.loss(h, s.loss_percent);
    }
    std::thread::sleep(s.lasting);
    for &h in hosts {
        lab.loss(h, 0);
    }
    let to_ns = now_ns();
    let after = tcp_total(&lab, hosts);
    std::thread::sleep(Duration::from_millis(500));
    let stopped = stop_all(&mut lab, &running);
    let seen = seen(&lab, running.observer.unwrap());
    let monotonic = check_monotonic(&seen);
    let within: Vec<f64> =
        gaps(&seen).into_iter().filter(|(at, _)| *at > from_ns && *at <= to_ns).map(|g| g.1).collect();
    let tcp = after.iter().map(|(k, v)| (k.clone(), v.saturating_sub(before.get(k).copied().unwrap_or(0)))).collect();
    Lossy {
        from_ns,
        to_ns,
        statuses: within.len(),
        gaps_ms: within,
        safe: safe_mode_periods(&recording(&lab, "pipeline"), stopped),
        arrivals: seen.iter().map(|s| s.at_ns).collect(),
        tcp,
        board_out: lab.stdout(running.procs["board"]),
        board_states: recorded_states(&recording(&lab, "board"), stopped),
        pipeline_path: path(&lab.stdout(running.procs["pipeline"])),
        epochs: epoch_changes(&seen),
        leadership: leadership(&lab, &running),
        beats: beat_lines(&lab, &running),
        monotonic,
    }
}

/// The boards' lines of standard error that contain any of `what`, each
/// prefixed with its process.
pub fn board_lines(lab: &Lab, running: &Running, what: &[&str]) -> Vec<String> {
    let mut lines = Vec::new();
    for b in &running.boards {
        if let Some(pid) = running.procs.get(b) {
            let said = lab.stderr(*pid);
            lines.extend(said.lines().filter(|l| what.iter().any(|w| l.contains(w))).map(|l| format!("{b}: {l}")));
        }
    }
    lines
}

/// The boards' lines on leading and stepping down, from their standard
/// error, each prefixed with its process.
pub fn leadership(lab: &Lab, running: &Running) -> Vec<String> {
    board_lines(lab, running, &[" leads at epoch ", " steps down"])
}

/// The boards' closing lines on the beats they heard over UDP.
pub fn beat_lines(lab: &Lab, running: &Running) -> Vec<String> {
    board_lines(lab, running, &[" heard over UDP"])
}

/// How many beats over UDP `board` said renewed the leader, from
/// [`beat_lines`], if it said.
pub fn beats_renewed(lines: &[String], board: &str) -> Option<u64> {
    let line = lines.iter().find(|l| l.starts_with(&format!("{board}: ")))?;
    line.split(", ").nth(1)?.split_whitespace().next()?.parse().ok()
}

impl Lossy {
    /// The agents' safe-mode rule as docs/protocol.md has it: a process
    /// enters safe mode only after 600 ms without status, and it enters it
    /// when none comes for longer. Checked on the observer's view of the
    /// same process (it is a client of the pipeline's process, so it gets
    /// what that process gets): each entry follows at least `quiet_ms`
    /// without status, and every time without status longer than
    /// `loud_ms` holds an entry.
    pub fn check_safe_mode_rule(&self, quiet_ms: f64, loud_ms: f64) -> Result<(), String> {
        for (entered, _) in &self.safe {
            if let Some(last) = self.arrivals.iter().filter(|a| *a <= entered).max() {
                let quiet = (entered - last) as f64 / 1e6;
                if quiet < quiet_ms {
                    return Err(format!("safe mode after only {quiet:.0} ms without status (at {entered})"));
                }
            }
        }
        for w in self.arrivals.windows(2) {
            let gap = (w[1] - w[0]) as f64 / 1e6;
            if gap > loud_ms && !self.safe.iter().any(|(e, _)| *e > w[0] && *e < w[1]) {
                return Err(format!("{gap:.0} ms without status (until {}) and no safe mode", w[1]));
            }
        }
        Ok(())
    }

    pub fn figures(&self) -> String {
        let (p50, p99, max) = percentiles(&self.gaps_ms);
        let over = |ms: f64| self.gaps_ms.iter().filter(|g| **g > ms).count();
        let k = |name: &str| self.tcp.get(name).copied().unwrap_or(0);
        format!(
            "{} statuses in {:.1} s; gaps p50 {p50:.0} ms, p99 {p99:.0} ms, max {max:.0} ms; over 300 ms: {}, over 450 ms: {}, \
             over 600 ms: {}; safe mode entered {} time(s); board: {}; leaders seen (epoch, board): {:?}; TCP (hosts \
             and relay): {} segments retransmitted, {} timeouts (RTO), {} loss probes (TLP), {} fast retransmits",
            self.statuses,
            (self.to_ns - self.from_ns) as f64 / 1e9,
            over(300.0),
            over(450.0),
            over(600.0),
            self.safe.len(),
            self.board_states.join(" -> "),
            self.epochs,
            k("TcpRetransSegs"),
            k("TcpExtTCPTimeouts"),
            k("TcpExtTCPLossProbes"),
            k("TcpExtTCPFastRetrans"),
        )
    }
}
