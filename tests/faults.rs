//! Faults between hosts: situ's distributed stack on test hosts made of
//! Linux network namespaces (tests/faults/lab.rs), with partitions, killed
//! processes, a restarted router, and delay and loss between the hosts.
//! Every test makes its own namespaces and removes them; a machine without
//! `ip`, `nft` or the privilege fails the test with the reason.
//! docs/reliability.md ("Faults between hosts") describes the scenarios and
//! their figures; the soak tests (`--ignored`) run them longer:
//! `cargo test -p situ --features zenoh --test faults -- --ignored --nocapture soak`.
#![cfg(feature = "zenoh")]

// The harness offers more than these tests use (the standby board's
// scenarios build on it).
#[path = "faults/lab.rs"]
#[allow(dead_code)]
mod lab;
#[path = "faults/scenarios.rs"]
#[allow(dead_code)]
mod scenarios;
#[path = "faults/stack.rs"]
#[allow(dead_code)]
mod stack;
#[path = "faults/standby.rs"]
#[allow(dead_code)]
mod standby;

use lab::Lab;
use scenarios::*;
use stack::*;
use std::time::Duration;

#[test]
fn figure_5_runs_across_three_hosts() {
    let mut lab = Lab::new(&["board", "sensors", "pipeline"]);
    let procs = fig5_peers();
    let deploy = write_deployment(&lab, "fig5", &procs, None);
    let running = start(&mut lab, &fig5_rules(), &deploy, &procs);
    let at = format!("tcp/{}:7449", lab.addr("pipeline"));
    let observer = observe(&mut lab, "pipeline", &at, "client", "fig5");
    for p in ["board", "sensors", "pipeline"] {
        wait_state(&mut lab, &running, p, "RO", LONG);
    }
    std::thread::sleep(Duration::from_secs(2));
    let stopped = stop_all(&mut lab, &running);
    assert_eq!(recorded_states(&recording(&lab, "board"), stopped), ["RO"], "{}", lab.outputs());
    for p in ["sensors", "pipeline"] {
        assert_eq!(path(&lab.stdout(running.procs[p])), ["RS", "RO"], "{p} followed RS -> RO:\n{}", lab.outputs());
    }
    let seen = seen(&lab, observer);
    check_monotonic(&seen).unwrap();
    assert!(seen.iter().any(|s| s.state == "RO"), "{seen:?}");
    let g: Vec<f64> = gaps(&seen).iter().map(|g| g.1).collect();
    let (p50, p99, max) = percentiles(&g);
    eprintln!(
        "baseline: {} statuses seen on the pipeline's host; gaps p50 {p50:.0} ms, p99 {p99:.0} ms, max {max:.0} ms",
        seen.len()
    );
    assert!(safe_mode_periods(&recording(&lab, "pipeline"), stopped).is_empty());
}

#[test]
fn a_host_cut_off_enters_safe_mode_and_leaves_it_when_joined_again() {
    let p = partition_pipeline(Duration::from_millis(1500));
    eprintln!(
        "partition 1.5 s: {:.0} ms without status on the cut host, back {:.0} ms after the heal; safe mode {:?} \
         (entered, left, ms from the cut); the sensors' host (not cut): {} safe mode(s)",
        p.gap_ms,
        p.back_after_ms,
        p.safe.iter().map(|(e, l)| (ms(e - p.cut_ns), l.map(|l| ms(l - p.cut_ns)))).collect::<Vec<_>>(),
        p.sensors_safe.len()
    );
    // The cut host heard nothing while cut, and entered safe mode in that time.
    assert!(p.gap_ms >= 1000.0, "{p:#?}");
    let during = p.safe.iter().find(|(e, _)| *e > p.cut_ns && *e < p.healed_ns + 1_000_000_000);
    let (_, left) = during.unwrap_or_else(|| panic!("no safe mode for the cut: {p:#?}"));
    // … and left it once joined again.
    assert!(left.is_some_and(|l| l > p.healed_ns), "{p:#?}");
    assert!(p.safe.iter().all(|(_, l)| l.is_some()), "every safe mode ends: {p:#?}");
    // The mission went on: the board stayed in RO, the pipeline follows it.
    assert_eq!(p.board_states, ["RO"], "{p:#?}");
    assert_eq!(p.pipeline_path, ["RS", "RO"], "{p:#?}");
}

#[test]
fn a_router_killed_and_started_again_carries_the_mission_on() {
    let r = restart_router(Duration::from_millis(200), Some("5s"), false);
    eprintln!("router restart: {}", router_figures(&r));
    assert!(r.safe.iter().all(|(_, l)| l.is_some()), "every safe mode ends: {r:#?}");
    assert_eq!(r.board_states, ["RO"], "{r:#?}");
    assert_eq!(r.pipeline_path, ["RS", "RO"], "{r:#?}");
}

#[test]
fn delay_and_loss_between_hosts_keep_the_safe_mode_rule() {
    let l = lossy_for_12_s(false);
    eprintln!("50 ms delay, 5 % loss, 12 s: {}", l.figures());
    l.monotonic.as_ref().unwrap_or_else(|e| panic!("{e}"));
    kept_the_safe_mode_rule_and_the_mission(&l);
}

/// 50 ms delay each way throughout, 5 % loss on every host for 12 s. The
/// sensors stale after 3 s: with the file's 500 ms, two losses in a row on
/// the sensors' link (or a loaded machine) rightly make it an emergency
/// and a stop, which is not what these tests are about (the soak runs the
/// file's 500 ms and reports it).
///
/// With two boards the boards beat over UDP too (`beats`), on routes with
/// Linux's own least RTO (200 ms): a segment lost twice stalls the boards'
/// TCP link for 600 ms, past the lease (450 ms), and without the datagrams
/// the follower took the silence for a dead leader (a false takeover, seen
/// in CI and in a soak; `soak_two_boards` counts them with and without).
fn lossy_for_12_s(two_boards: bool) -> scenarios::Lossy {
    delay_and_loss(&LossySettings {
        delay_ms: 50,
        loss_percent: 5,
        lasting: Duration::from_secs(12),
        rto_min_ms: None,
        stale: Some("3s"),
        two_boards,
        beats: two_boards,
    })
}

/// Statuses kept coming (one every 200 ms when nothing is lost, every
/// 50 ms from a standby group's leader), the safe-mode rule held, every
/// safe mode ended, and the board stayed in RO.
fn kept_the_safe_mode_rule_and_the_mission(l: &scenarios::Lossy) {
    assert!(l.statuses >= 20, "{}", l.figures());
    l.check_safe_mode_rule(500.0, 1500.0).unwrap_or_else(|e| panic!("{e}: {}", l.figures()));
    assert!(l.safe.iter().all(|(_, left)| left.is_some()), "every safe mode ends: {}", l.figures());
    assert_eq!(l.board_states, ["RO"], "the mission went on: {}", l.figures());
}

#[test]
fn the_standby_board_takes_over_from_a_killed_leader_and_the_mission_goes_on() {
    // The sensors stale after 3 s, as in tests/standby_cmd.rs: a loaded
    // machine must not turn the takeover into an emergency (the soak runs
    // Fig. 5's own 500 ms too).
    let t = standby::kill_leading_board(Some("3s"));
    eprintln!(
        "takeover: the first status of a higher epoch ({} from {:?}, was {} from {:?}) {:.0} ms after the kill; \
         {:.0} ms without status on the pipeline's host; the pipeline's safe mode: {:?}",
        t.epoch_after,
        t.board_after,
        t.epoch_before,
        t.board_before,
        t.takeover_ms,
        t.gap_ms,
        t.safe.iter().map(|(e, l)| (ms(e - t.killed_ns), l.map(|l| ms(l - t.killed_ns)))).collect::<Vec<_>>()
    );
    // kill_leading_board checked that a higher epoch came and that no
    // epoch seen went back.
    assert_eq!(t.board_after.as_deref(), Some("standby"), "{t:#?}");
    assert!(t.safe.iter().all(|(_, l)| l.is_some()), "every safe mode ends: {t:#?}");
    // The mission went on: the standby holds RO, the pipeline follows it.
    assert!(!t.standby_states.iter().any(|s| s == "EM" || s == "SP"), "{t:#?}");
    assert_eq!(t.pipeline_path, ["RS", "RO"], "{t:#?}");
}

#[test]
fn the_leader_cut_off_is_replaced_and_steps_down_when_joined_again() {
    let c = standby::partition_leader(Duration::from_millis(1500), Some("3s"));
    eprintln!(
        "leader cut off 1.5 s: a status of a higher epoch ({} from {:?}) {:.0} ms after the cut; the old leader's \
         epoch reached the pipeline's host {} more time(s) after that (ignored by agents: a lower epoch), the last \
         {:?} ms after the heal; at the end epoch {} from {:?}; the pipeline's safe mode: {:?}",
        c.epoch_after,
        c.board_after,
        c.takeover_ms,
        c.old_after_takeover,
        c.last_old_after_heal_ms.map(|m| m.round()),
        c.epoch_last,
        c.board_last,
        c.safe.iter().map(|(e, l)| (ms(e - c.cut_ns), l.map(|l| ms(l - c.cut_ns)))).collect::<Vec<_>>()
    );
    assert_eq!(c.board_after.as_deref(), Some("standby"), "{c:#?}");
    // The old leader, joined again, stepped down: the highest epoch is
    // still the standby's, and the old one stopped coming (what it sent
    // while cut off arrives after the heal, after TCP's backoff: up to
    // about 2 s; a leader that did not step down would go on for the 5 s
    // the run lasts).
    assert_eq!((c.epoch_last, c.board_last.as_deref()), (c.epoch_after, Some("standby")), "{c:#?}");
    assert!(c.last_old_after_heal_ms.is_none_or(|ms| ms < 4000.0), "{c:#?}");
    assert!(c.safe.iter().all(|(_, l)| l.is_some()), "every safe mode ends: {c:#?}");
    assert!(!c.standby_states.iter().any(|s| s == "EM" || s == "SP"), "{c:#?}");
    assert_eq!(c.pipeline_path, ["RS", "RO"], "{c:#?}");
}

#[test]
fn two_boards_under_delay_and_loss_keep_one_leader() {
    // The standby group's beats, log and acknowledgements cross the same
    // relay and the same loss as the statuses, and so do the beats'
    // datagrams: the follower must not take a stalled TCP link for a dead
    // leader (a segment lost twice stalls it for 600 ms, past the 450 ms
    // lease; a lost datagram is only one beat of the leader's fewer).
    let l = lossy_for_12_s(true);
    // (With one epoch throughout, nothing can go back: `l.monotonic`.)
    eprintln!("two boards, 50 ms delay, 5 % loss, 12 s: {}", l.figures());
    // One leader throughout: every status the agents' host saw carried the
    // first leader's epoch, and the standby never said it leads.
    assert_eq!(l.epochs.len(), 1, "a false takeover: {:?}\n{}", l.leadership, l.figures());
    assert_eq!(l.epochs[0].1.as_deref(), Some("board"), "{}", l.figures());
    assert!(l.epochs[0].0.is_some(), "a standby group's statuses carry their epoch: {}", l.figures());
    assert!(
        !l.leadership.iter().any(|x| x.starts_with("standby:") && x.contains(" leads at epoch ")),
        "{:?}",
        l.leadership
    );
    kept_the_safe_mode_rule_and_the_mission(&l);
    // The datagrams crossed the relay and the loss: the standby heard the
    // leader's beats over UDP (20 a second; 5 % lost), and they renewed
    // the leader it heard over Zenoh.
    let renewed = scenarios::beats_renewed(&l.beats, "standby");
    assert!(renewed.is_some_and(|n| n >= 100), "beats over UDP: {:?}", l.beats);
}

#[test]
fn a_stalled_tcp_link_between_the_boards_is_no_takeover_with_beats() {
    // Every TCP segment from the leader's host to the standby's dropped for
    // 1.5 s (three leases): Zenoh says nothing to the standby, but the
    // leader's datagrams pass and keep it alive there.
    let t = standby::stall_tcp_between_boards(Duration::from_millis(1500), true);
    assert_eq!(t.epochs.len(), 1, "a takeover: {t:#?}");
    assert_eq!(t.epochs[0].1.as_deref(), Some("board"), "{t:#?}");
    assert!(!t.leadership.iter().any(|l| l.starts_with("standby:") && l.contains(" leads at epoch ")), "{t:#?}");
    assert!(t.standby_err.contains("hears the boards' beats on udp/"), "{t:#?}");
    let renewed = scenarios::beats_renewed(&t.beats, "standby");
    assert!(renewed.is_some_and(|n| n >= 20), "{t:#?}");
}

#[test]
fn without_beats_a_stalled_tcp_link_between_the_boards_is_a_takeover() {
    // The same stall without `beats`: the standby hears nothing for longer
    // than its lease and leads (a false takeover, which `beats` prevents;
    // this is what makes the test above mean something). The old leader
    // hears the standby's statuses (that way TCP flows) and steps down.
    let t = standby::stall_tcp_between_boards(Duration::from_millis(1500), false);
    assert!(t.leadership.iter().any(|l| l.starts_with("standby:") && l.contains(" leads at epoch ")), "{t:#?}");
    assert!(t.leadership.iter().any(|l| l.contains("board `board` steps down")), "{t:#?}");
    assert_eq!(t.epochs.last().and_then(|e| e.1.as_deref()), Some("standby"), "{t:#?}");
    assert!(t.beats.is_empty(), "{t:#?}");
}

#[test]
fn a_router_down_longer_than_the_lease_under_two_boards_ends_with_one_leader() {
    // Down for 1 s: the boards, clients of the router, are cut from each
    // other for longer than the lease (450 ms, 500 ms for the standby), so
    // the standby leads while the old leader still believes it leads;
    // once the router is back, each hears the other and the lower epoch
    // steps down. (A 200 ms restart, the soak's, usually ends before the
    // lease: no takeover.)
    let r = restart_router(Duration::from_millis(1000), Some("5s"), true);
    eprintln!("router down 1 s, two boards: {}; leaders seen (epoch, board): {:?}", router_figures(&r), r.epochs);
    // restart_router checked that `seq` never went back within an epoch.
    // The standby took over while the router was down …
    let boards: Vec<Option<&str>> = r.epochs.iter().map(|e| e.1.as_deref()).collect();
    assert!(r.epochs.len() >= 2 && boards.contains(&Some("standby")), "no takeover: {r:#?}");
    // … and once the router was back one leader remained: the statuses of
    // the last second before the stop are of one epoch, the highest seen,
    // and the old leader said it steps down.
    assert_eq!(r.last_second.len(), 1, "two leaders at the end: {r:#?}");
    let highest = r.epochs.iter().filter_map(|e| e.0).max();
    assert_eq!(r.last_second[0].0, highest, "{r:#?}");
    assert!(r.errs.contains("board `board` steps down"), "{r:#?}");
    assert!(r.safe.iter().all(|(_, l)| l.is_some()), "every safe mode ends: {r:#?}");
    // The mission went on: neither board went to an emergency, the
    // pipeline followed RS -> RO only.
    for states in [&r.board_states, &r.standby_states] {
        assert!(!states.iter().any(|s| s == "EM" || s == "SP"), "{r:#?}");
    }
    assert_eq!(r.pipeline_path, ["RS", "RO"], "{r:#?}");
}

/// `SITU_SOAK_ROUNDS` (10) kills of the leading board, each on a fresh
/// lab, with the sensors stale after 3 s, then with Fig. 5's own 500 ms.
#[test]
#[ignore = "a benchmark: cargo test -p situ --features zenoh --test faults -- --ignored --nocapture soak"]
fn soak_takeover() {
    // SITU_SOAK_FILE_STALE=1: only Fig. 5's own 500 ms.
    let variants: &[Option<&str>] =
        if std::env::var_os("SITU_SOAK_FILE_STALE").is_some() { &[None] } else { &[Some("3s"), None] };
    for &stale in variants {
        let (mut takeovers, mut gaps, mut safe, mut emergencies) = (Vec::new(), Vec::new(), 0, 0);
        for _ in 0..env_or("SITU_SOAK_ROUNDS", 10) {
            let t = standby::kill_leading_board(stale);
            takeovers.push(t.takeover_ms);
            gaps.push(t.gap_ms);
            safe += t.safe.len();
            if t.standby_states.iter().any(|s| s == "EM") {
                emergencies += 1;
                eprintln!("soak: the new leader went {}: {t:#?}", t.standby_states.join(" -> "));
            }
        }
        let (t50, t99, tmax) = percentiles(&takeovers);
        let (g50, g99, gmax) = percentiles(&gaps);
        eprintln!(
            "soak: {} kills of the leading board (sensors stale after {}): from the kill to a status of a higher \
             epoch p50 {t50:.0} ms, p99 {t99:.0} ms, max {tmax:.0} ms; time without status p50 {g50:.0} ms, p99 \
             {g99:.0} ms, max {gmax:.0} ms; the pipeline entered safe mode {safe} time(s); the new leader went to EM \
             {emergencies} time(s)",
            takeovers.len(),
            stale.unwrap_or("500ms")
        );
    }
}

/// A router restart's figures, in words; panics if no status came after it.
fn router_figures(r: &scenarios::RouterRestart) -> String {
    let (Some(gap_ms), Some(back_after_ms)) = (r.gap_ms, r.back_after_ms) else {
        panic!("no status after the restart: {r:#?}")
    };
    format!(
        "{gap_ms:.0} ms without status on the pipeline's host, the first {back_after_ms:.0} ms after the new router \
         started; the pipeline's safe mode: {:?} (entered, left, ms from the kill)",
        r.safe.iter().map(|(e, l)| (ms(e - r.killed_ns), l.map(|l| ms(l - r.killed_ns)))).collect::<Vec<_>>()
    )
}

fn ms(ns: u64) -> i64 {
    (ns / 1_000_000) as i64
}

/// A figure of the environment, or its default.
fn env_or(name: &str, default: u64) -> u64 {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

/// `SITU_SOAK_SECONDS` (60) of 50 ms delay and 5 % loss, with Linux's
/// 200 ms least RTO and with `rto_min 20ms`, on Fig. 5 as it is (the
/// sensors stale after 500 ms).
#[test]
#[ignore = "a benchmark: cargo test -p situ --features zenoh --test faults -- --ignored --nocapture soak"]
fn soak_delay_and_loss() {
    let lasting = Duration::from_secs(env_or("SITU_SOAK_SECONDS", 60));
    for rto_min_ms in [None, Some(20)] {
        let s = LossySettings {
            delay_ms: 50,
            loss_percent: 5,
            lasting,
            rto_min_ms,
            stale: None,
            two_boards: false,
            beats: false,
        };
        let l = delay_and_loss(&s);
        let rto = rto_min_ms.map_or("200 ms (Linux's)".to_string(), |ms| format!("{ms} ms"));
        eprintln!("soak: 50 ms delay, 5 % loss, rto_min {rto}: {}", l.figures());
        if let Err(e) = l.check_safe_mode_rule(500.0, 1500.0) {
            eprintln!("soak: the safe-mode rule: {e}");
        }
    }
}

/// `SITU_SOAK_ROUNDS` (10) router restarts, each on a fresh lab, with
/// the sensors stale after 5 s, then as many with Fig. 5's own 500 ms
/// (where the restart may be an emergency: the rules' decision).
#[test]
#[ignore = "a benchmark: cargo test -p situ --features zenoh --test faults -- --ignored --nocapture soak"]
fn soak_router_restart() {
    for stale in [Some("5s"), None] {
        let (mut gaps, mut backs, mut safe, mut stopped) = (Vec::new(), Vec::new(), 0, 0);
        for _ in 0..env_or("SITU_SOAK_ROUNDS", 10) {
            let r = restart_router(Duration::from_millis(200), stale, false);
            gaps.extend(r.gap_ms);
            backs.extend(r.back_after_ms);
            safe += r.safe.len();
            stopped += usize::from(r.board_states.iter().any(|s| s == "EM"));
        }
        let (g50, _, gmax) = percentiles(&gaps);
        let (b50, _, bmax) = percentiles(&backs);
        eprintln!(
            "soak: {} router restarts with a status after (down 200 ms, sensors stale after {}): time without status p50 {g50:.0} ms, \
             max {gmax:.0} ms; from the new router's start to a status p50 {b50:.0} ms, max {bmax:.0} ms; the \
             pipeline entered safe mode {safe} time(s); the board went to EM {stopped} time(s)",
            gaps.len(),
            stale.unwrap_or("500ms")
        );
    }
}

/// `SITU_SOAK_ROUNDS` (10) partitions of 1.5 s, each on a fresh lab.
#[test]
#[ignore = "a benchmark: cargo test -p situ --features zenoh --test faults -- --ignored --nocapture soak"]
fn soak_partition() {
    let (mut gaps, mut backs, mut entered, mut left) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut emergencies = 0;
    for _ in 0..env_or("SITU_SOAK_ROUNDS", 10) {
        let p = partition_pipeline(Duration::from_millis(1500));
        if p.board_states.iter().any(|s| s == "EM") {
            emergencies += 1;
            eprintln!(
                "soak: the board went {} in a partition of the pipeline's host: {p:#?}",
                p.board_states.join(" -> ")
            );
        }
        gaps.push(p.gap_ms);
        backs.push(p.back_after_ms);
        for (e, l) in &p.safe {
            entered.push(e.saturating_sub(p.cut_ns) as f64 / 1e6);
            if let Some(l) = l {
                left.push(l.saturating_sub(p.healed_ns) as f64 / 1e6);
            }
        }
    }
    let f = |v: &[f64]| {
        let (p50, _, max) = percentiles(v);
        format!("p50 {p50:.0} ms, max {max:.0} ms")
    };
    eprintln!(
        "soak: {} partitions of 1.5 s: time without status {}; first status after the heal {}; safe mode entered \
         after the cut {}, left after the heal {}; the board went to EM {emergencies} time(s)",
        gaps.len(),
        f(&gaps),
        f(&backs),
        f(&entered),
        f(&left)
    );
}

/// A standby group under the network's faults: `SITU_SOAK_SECONDS` (60)
/// of 50 ms delay and 5 % loss (false takeovers counted), then
/// `SITU_SOAK_ROUNDS` (10) router restarts (takeovers, the leaders at the
/// end, the time without status), the sensors stale after 3 s and 5 s.
#[test]
#[ignore = "a benchmark: cargo test -p situ --features zenoh --test faults -- --ignored --nocapture soak"]
fn soak_two_boards() {
    let lasting = Duration::from_secs(env_or("SITU_SOAK_SECONDS", 60));
    // Which of the soak's settings: `beats` (UDP beats, Linux's RTO),
    // `tcp` (Zenoh only, Linux's RTO), `rto20` (Zenoh only, rto_min 20 ms);
    // all three by default.
    let only = std::env::var("SITU_SOAK_LOSSY").unwrap_or_default();
    let loss_percent = env_or("SITU_SOAK_LOSS", 5) as u8;
    for (name, rto_min_ms, beats) in [("beats", None, true), ("tcp", None, false), ("rto20", Some(20), false)] {
        if !only.is_empty() && !only.split(',').any(|o| o == name) {
            continue;
        }
        let s = LossySettings {
            delay_ms: 50,
            loss_percent,
            lasting,
            rto_min_ms,
            stale: Some("3s"),
            two_boards: true,
            beats,
        };
        let l = delay_and_loss(&s);
        let rto = rto_min_ms.map_or("200 ms (Linux's)".to_string(), |ms| format!("{ms} ms"));
        eprintln!(
            "soak: two boards, 50 ms delay, {loss_percent} % loss, rto_min {rto}, beats over UDP {beats}: false takeovers \
             {}; {}; \
             the boards said: {:?}",
            l.epochs.iter().map(|e| e.0).collect::<std::collections::BTreeSet<_>>().len().saturating_sub(1),
            l.figures(),
            l.leadership
        );
    }
    let (mut gaps, mut backs, mut safe, mut takeovers, mut two_at_end, mut stopped) =
        (Vec::new(), Vec::new(), 0, 0, 0, 0);
    let rounds = env_or("SITU_SOAK_ROUNDS", 10);
    if rounds == 0 {
        return;
    }
    for _ in 0..rounds {
        let r = restart_router(Duration::from_millis(200), Some("5s"), true);
        gaps.extend(r.gap_ms);
        backs.extend(r.back_after_ms);
        safe += r.safe.len();
        takeovers += usize::from(r.epochs.len() > 1);
        two_at_end += usize::from(r.last_second.len() > 1);
        stopped += usize::from(r.board_states.iter().chain(&r.standby_states).any(|s| s == "EM"));
    }
    let (g50, _, gmax) = percentiles(&gaps);
    let (b50, _, bmax) = percentiles(&backs);
    eprintln!(
        "soak: {rounds} router restarts under two boards (down 200 ms, sensors stale after 5 s): time without status \
         p50 {g50:.0} ms, max {gmax:.0} ms; from the new router's start to a status p50 {b50:.0} ms, max {bmax:.0} \
         ms; a takeover in {takeovers}; two leaders in the last second {two_at_end}; the pipeline entered safe mode \
         {safe} time(s); a board went to EM {stopped} time(s)"
    );
}
