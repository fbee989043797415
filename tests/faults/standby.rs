//! The standby board's scenario (issue 31): Fig. 5 with two boards, the
//! leader killed. A deployment marks two processes `board = true` (the
//! first listed leads at start); every status carries `epoch` (the highest
//! wins) and `board` (the leading process's name).

use super::lab::{Lab, Pid};
use super::scenarios::LONG;
use super::stack::*;
use std::time::{Duration, Instant};

/// Fig. 5 as peers with a second board: `board` (leads at start) and
/// `standby` on hosts of their own; the agents' processes meet both.
pub fn fig5_two_boards() -> Vec<Proc> {
    let mut procs = fig5_peers();
    procs.insert(
        1,
        Proc {
            name: "standby",
            host: "standby",
            board: true,
            agents: &[],
            mode: "peer",
            listen: Some(7447),
            connect: &["board"],
        },
    );
    for p in &mut procs {
        match p.name {
            "sensors" => p.connect = &["board", "standby"],
            "pipeline" => p.connect = &["board", "standby", "sensors"],
            _ => {}
        }
    }
    procs
}

/// Fig. 5's processes as clients of a router ([`fig5_router`]) with a
/// second board, `standby`, on a host of its own, a client of the router
/// too.
pub fn fig5_router_two_boards() -> Vec<Proc> {
    let mut procs = fig5_router();
    let mut standby = procs.iter().find(|p| p.name == "board").expect("the board").clone();
    (standby.name, standby.host) = ("standby", "standby");
    procs.insert(2, standby);
    procs
}

/// What killing the leading board did.
#[derive(Debug)]
pub struct Takeover {
    pub killed_ns: u64,
    /// The epoch and board of the last status before the kill.
    pub epoch_before: u64,
    pub board_before: Option<String>,
    /// From the kill to the first status of a higher epoch on the
    /// pipeline's host (ms).
    pub takeover_ms: f64,
    pub epoch_after: u64,
    pub board_after: Option<String>,
    /// The pipeline host's time without status before the first status of
    /// the new epoch (ms).
    pub gap_ms: f64,
    /// The pipeline's safe-mode periods (ns).
    pub safe: Vec<(u64, Option<u64>)>,
    pub standby_out: String,
    pub standby_err: String,
    pub pipeline_out: String,
    /// The states the standby's recording went through before the
    /// stop, and the path the pipeline followed.
    pub standby_states: Vec<String>,
    pub pipeline_path: Vec<String>,
}

/// Fig. 5 with two boards, each process on its host, the observer on the
/// pipeline's: once every agent follows RO and the observer has a status
/// with an epoch, 500 ms later. The sensors' `stale after` is `stale`
/// (`fig5_rules_with_stale`), or the file's 500 ms. Returns the
/// observer's latest status, with its epoch.
fn two_boards_in_ro(stale: Option<&str>) -> (Lab, Running, Pid, Seen, u64) {
    two_boards_in_ro_with(stale, true)
}

/// As [`two_boards_in_ro`], the boards with `beats` or not.
fn two_boards_in_ro_with(stale: Option<&str>, beats: bool) -> (Lab, Running, Pid, Seen, u64) {
    let mut lab = Lab::new(&["board", "standby", "sensors", "pipeline"]);
    let procs = fig5_two_boards();
    let rules = match stale {
        Some(stale) => fig5_rules_with_stale(&lab, stale),
        None => fig5_rules(),
    };
    // The boards beat over UDP too, as advised between hosts: a kill or a
    // cut host silences the datagrams as well.
    let deploy = if beats {
        write_deployment_with_beats(&lab, "fig5", &procs, None)
    } else {
        write_deployment(&lab, "fig5", &procs, None)
    };
    let mut running = start(&mut lab, &rules, &deploy, &procs);
    let at = format!("tcp/{}:7449", lab.addr("pipeline"));
    let observer = observe(&mut lab, "pipeline", &at, "client", "fig5");
    running.observer = Some(observer);
    for p in ["sensors", "pipeline"] {
        wait_state(&mut lab, &running, p, "RO", LONG);
    }
    wait_seen(&lab, observer, 0, LONG, |s| s.state == "RO" && s.epoch.is_some())
        .unwrap_or_else(|| panic!("no status with an epoch in RO\n{}", lab.outputs()));
    std::thread::sleep(Duration::from_millis(500));
    let before = seen(&lab, observer).pop().expect("a status before the fault");
    let epoch = before.epoch.expect("statuses carry their epoch");
    (lab, running, observer, before, epoch)
}

/// Fig. 5 with two boards on four hosts (`board`, `standby`, `sensors`,
/// `pipeline`); once the observer on the pipeline's host (a client of the
/// pipeline's process: what it gets) has seen RO from the leader, the
/// leader's process is killed (SIGKILL); the run goes on until the
/// observer has had a status of a higher epoch and 5 statuses after it.
/// Panics if no higher epoch comes within a minute, or if an epoch seen
/// ever goes back.
///
/// The sensors' `stale after` is `stale` (`fig5_rules_with_stale`), or the
/// file's 500 ms.
pub fn kill_leading_board(stale: Option<&str>) -> Takeover {
    let (mut lab, mut running, observer, before, epoch_before) = two_boards_in_ro(stale);
    let killed_ns = now_ns();
    lab.kill9(running.procs.remove("board").expect("the leading board"));
    let after = wait_seen(&lab, observer, killed_ns, LONG, |s| s.epoch.is_some_and(|e| e > epoch_before))
        .unwrap_or_else(|| panic!("no status of an epoch above {epoch_before} after the kill\n{}", lab.outputs()));
    // 5 statuses more, or the new leader ended (its rules reached a final
    // state: the mission's end, which the test judges).
    let end = Instant::now() + LONG;
    while seen(&lab, observer).iter().filter(|s| s.at_ns > after.at_ns).count() < 5 {
        if lab.wait(running.procs["standby"], Duration::ZERO).is_some() {
            std::thread::sleep(Duration::from_secs(1));
            break;
        }
        assert!(Instant::now() < end, "statuses stopped after the takeover\n{}", lab.outputs());
        std::thread::sleep(Duration::from_millis(50));
    }
    let stopped = stop_all(&mut lab, &running);
    let all = seen(&lab, observer);
    check_monotonic(&all).unwrap_or_else(|e| panic!("{e}"));
    // The time without status: up to the first status of the new epoch
    // (one of the old leader's may arrive just after the kill).
    let (gap_ms, _) = gap_across(&all, after.at_ns - 1).expect("statuses before and after the takeover");
    Takeover {
        killed_ns,
        epoch_before,
        board_before: before.board,
        takeover_ms: after.at_ns.saturating_sub(killed_ns) as f64 / 1e6,
        epoch_after: after.epoch.unwrap_or(0),
        board_after: after.board,
        gap_ms,
        safe: safe_mode_periods(&recording(&lab, "pipeline"), stopped),
        standby_out: lab.stdout(running.procs["standby"]),
        standby_err: lab.stderr(running.procs["standby"]),
        pipeline_out: lab.stdout(running.procs["pipeline"]),
        standby_states: recorded_states(&recording(&lab, "standby"), stopped),
        pipeline_path: path(&lab.stdout(running.procs["pipeline"])),
    }
}

/// What cutting the leading board's host off did.
#[derive(Debug)]
pub struct LeaderCut {
    pub cut_ns: u64,
    pub healed_ns: u64,
    pub epoch_before: u64,
    /// From the cut to the first status of a higher epoch on the pipeline's
    /// host (ms), and that status's epoch and board.
    pub takeover_ms: f64,
    pub epoch_after: u64,
    pub board_after: Option<String>,
    /// Statuses of the old leader's epoch that reached the pipeline's host
    /// after the takeover (agents ignore them: a lower epoch), and the last
    /// one's arrival after the heal (ms; `None`: none after the heal).
    pub old_after_takeover: usize,
    pub last_old_after_heal_ms: Option<f64>,
    /// The highest epoch the observer saw at the end, and from whom.
    pub epoch_last: u64,
    pub board_last: Option<String>,
    pub safe: Vec<(u64, Option<u64>)>,
    pub standby_states: Vec<String>,
    pub pipeline_path: Vec<String>,
    pub board_err: String,
}

/// Fig. 5 with two boards on four hosts, as [`kill_leading_board`]; once
/// the observer has seen RO from the leader, the leader's host is cut off
/// for `cut` (at least until a status of a higher epoch came), then joined
/// again, and the run goes on for 5 s more.
pub fn partition_leader(cut: Duration, stale: Option<&str>) -> LeaderCut {
    let (mut lab, running, observer, _, epoch_before) = two_boards_in_ro(stale);
    let cut_ns = now_ns();
    lab.partition("board");
    let after = wait_seen(&lab, observer, cut_ns, LONG, |s| s.epoch.is_some_and(|e| e > epoch_before))
        .unwrap_or_else(|| panic!("no status of an epoch above {epoch_before} after the cut\n{}", lab.outputs()));
    let until = cut_ns + cut.as_nanos() as u64;
    std::thread::sleep(Duration::from_nanos(until.saturating_sub(now_ns())));
    let healed_ns = now_ns();
    lab.heal("board");
    std::thread::sleep(Duration::from_secs(5));
    let stopped = stop_all(&mut lab, &running);
    let all = seen(&lab, observer);
    let old: Vec<u64> =
        all.iter().filter(|s| s.at_ns > after.at_ns && s.epoch == Some(epoch_before)).map(|s| s.at_ns).collect();
    let last = all.iter().filter(|s| s.epoch.is_some()).max_by_key(|s| (s.epoch, s.at_ns)).cloned();
    LeaderCut {
        cut_ns,
        healed_ns,
        epoch_before,
        takeover_ms: after.at_ns.saturating_sub(cut_ns) as f64 / 1e6,
        epoch_after: after.epoch.unwrap_or(0),
        board_after: after.board,
        old_after_takeover: old.len(),
        last_old_after_heal_ms: old.iter().filter(|t| **t > healed_ns).max().map(|t| (t - healed_ns) as f64 / 1e6),
        epoch_last: last.as_ref().and_then(|s| s.epoch).unwrap_or(0),
        board_last: last.and_then(|s| s.board),
        safe: safe_mode_periods(&recording(&lab, "pipeline"), stopped),
        standby_states: recorded_states(&recording(&lab, "standby"), stopped),
        pipeline_path: path(&lab.stdout(running.procs["pipeline"])),
        board_err: lab.stderr(running.procs["board"]),
    }
}

/// What a stall of the boards' TCP link did.
#[derive(Debug)]
pub struct TcpStall {
    /// The (epoch, board) of the statuses the pipeline's host saw, as they
    /// changed over the run.
    pub epochs: Vec<(Option<u64>, Option<String>)>,
    /// The boards' lines on leading and stepping down.
    pub leadership: Vec<String>,
    /// The boards' closing lines on the beats they heard over UDP.
    pub beats: Vec<String>,
    pub standby_err: String,
}

/// Fig. 5 with two boards on four hosts, with `beats` or not; once the
/// observer has seen RO from the leader, every TCP segment from the
/// leader's host to the standby's is dropped for `stall` (datagrams pass),
/// then let through again, and the run goes on for 3 s more.
pub fn stall_tcp_between_boards(stall: Duration, beats: bool) -> TcpStall {
    let (mut lab, running, observer, _, _) = two_boards_in_ro_with(Some("3s"), beats);
    lab.drop_tcp_from("standby", Some("board"));
    std::thread::sleep(stall);
    lab.drop_tcp_from("standby", None);
    std::thread::sleep(Duration::from_secs(3));
    let _ = stop_all(&mut lab, &running);
    let all = seen(&lab, observer);
    TcpStall {
        epochs: super::scenarios::epoch_changes(&all),
        leadership: super::scenarios::leadership(&lab, &running),
        beats: super::scenarios::beat_lines(&lab, &running),
        standby_err: lab.stderr(running.procs["standby"]),
    }
}
