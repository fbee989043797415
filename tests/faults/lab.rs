//! Test hosts as Linux network namespaces: a `Lab` is a "switch" namespace
//! with a Linux bridge, and one namespace per host joined to it by a veth
//! pair, each host with its own address in a /24 of the lab's own. Faults
//! are made from outside the hosts: a partition sets the switch's end of a
//! host's veth down; loss is an nftables rule in the host (`numgen random
//! mod 100 < P drop` on what reaches it from other hosts); delay is a relay of
//! our own (`relay.py`) in the switch namespace that holds each chunk of a
//! TCP stream for D ms before passing it on.
//!
//! Everything the lab made goes away when it is dropped (a panicking test
//! included): its processes are killed (SIGKILL) and reaped, its namespaces
//! deleted (which deletes their interfaces and nftables rules). Namespaces
//! of a test process that died without dropping its lab (`situ-PID-…` of a
//! PID that no longer runs) are deleted when the next lab is made.
//!
//! A missing tool or privilege fails the test with the reason; nothing is
//! skipped (`bash scripts/install-net-tools.sh` installs `ip` and `nft`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Once;
use std::time::{Duration, Instant};

/// Every namespace of every lab starts with this, then `PID-N-`.
const PREFIX: &str = "situ-";

/// The nftables table the lab writes in a host.
const TABLE: &str = "situlab";

static NEXT: AtomicUsize = AtomicUsize::new(0);
static SWEEP: Once = Once::new();

/// A process the lab started (an index into the lab's processes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pid(usize);

struct Proc {
    label: String,
    child: Child,
    out: PathBuf,
    err: PathBuf,
    status: Option<ExitStatus>,
}

/// What the lab's nftables table in one host does.
#[derive(Debug, Clone, Copy, Default)]
struct Filter {
    /// Percent of the packets the host sends to other hosts that are dropped.
    loss: u8,
    /// Packets to other hosts are dropped unless they go to the switch's
    /// address (the relay): every link between hosts crosses the relay.
    only_switch: bool,
    /// TCP segments from this host (by its index) are dropped; UDP passes.
    tcp_from: Option<usize>,
}

/// A relay of TCP streams in the switch namespace (`relay.py`).
#[derive(Debug, Clone)]
pub struct Relay {
    pub pid: Pid,
    /// The relay's port for each target `(host, port)`.
    ports: BTreeMap<(String, u16), u16>,
    /// The relay's UDP port for each datagram target `(host, port)`.
    udp_ports: BTreeMap<(String, u16), u16>,
    addr: String,
}

impl Relay {
    /// The Zenoh endpoint through the relay to `host`'s `port`.
    pub fn endpoint(&self, host: &str, port: u16) -> String {
        self.via(&self.ports, "tcp", host, port)
    }

    /// The UDP endpoint through the relay to `host`'s `port`.
    pub fn udp_endpoint(&self, host: &str, port: u16) -> String {
        self.via(&self.udp_ports, "udp", host, port)
    }

    fn via(&self, routes: &BTreeMap<(String, u16), u16>, proto: &str, host: &str, port: u16) -> String {
        let p = routes
            .get(&(host.to_string(), port))
            .unwrap_or_else(|| panic!("the relay has no {proto} route to {host}:{port}"));
        format!("{proto}/{}:{p}", self.addr)
    }
}

pub struct Lab {
    /// `situ-PID-N-`: every namespace of this lab starts with it.
    prefix: String,
    /// The first three bytes of the lab's /24.
    net: [u8; 3],
    hosts: Vec<String>,
    filters: BTreeMap<String, Filter>,
    /// Namespaces made so far, deleted on drop.
    made: Vec<String>,
    procs: Vec<Proc>,
    dir: tempfile::TempDir,
}

/// Runs a command to its end; its standard error on failure.
fn run(cmd: &mut Command) -> Result<String, String> {
    let what = format!("{:?}", cmd);
    let o = cmd.stdin(Stdio::null()).output().map_err(|e| format!("{what}: cannot start: {e}"))?;
    if o.status.success() {
        Ok(String::from_utf8_lossy(&o.stdout).into_owned())
    } else {
        Err(format!("{what}: {}: {}", o.status, String::from_utf8_lossy(&o.stderr).trim()))
    }
}

fn ip(args: &[&str]) -> Result<String, String> {
    run(Command::new("ip").args(args))
}

/// The tools and the privilege the lab needs, or why not.
fn check_tools() -> Result<(), String> {
    for (tool, arg) in [("ip", "-V"), ("nft", "--version"), ("python3", "--version")] {
        Command::new(tool).arg(arg).output().map_err(|e| {
            format!("`{tool}` is needed by the fault tests ({e}): run `bash scripts/install-net-tools.sh` (iproute2, nftables)")
        })?;
    }
    Ok(())
}

/// Deletes the namespaces of labs whose test process is gone, and kills
/// what still runs in them.
fn sweep_stale() {
    let Ok(list) = ip(&["netns", "list"]) else { return };
    for name in list.lines().filter_map(|l| l.split_whitespace().next()) {
        let Some(rest) = name.strip_prefix(PREFIX) else { continue };
        let Some(pid) = rest.split('-').next().and_then(|p| p.parse::<u32>().ok()) else { continue };
        if pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists() {
            // What that test started still runs in them (it died without
            // its lab's drop): those processes first, by their ids.
            for p in ip(&["netns", "pids", name]).unwrap_or_default().split_whitespace() {
                if let Ok(p) = p.parse::<i32>() {
                    // SAFETY: kill(2) with a process id and a signal number.
                    unsafe { libc::kill(p, libc::SIGKILL) };
                }
            }
            let _ = ip(&["netns", "del", name]);
        }
    }
}

impl Lab {
    /// A lab with these hosts (short names, e.g. `board`, `sensors`), all
    /// reachable from each other through the switch. Panics with the reason
    /// when the machine cannot make it (no `ip`, no privilege).
    pub fn new(hosts: &[&str]) -> Lab {
        if let Err(e) = check_tools() {
            panic!("{e}");
        }
        SWEEP.call_once(sweep_stale);
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let pid = std::process::id();
        let mut lab = Lab {
            prefix: format!("{PREFIX}{pid}-{n}-"),
            net: [10, 20 + (pid % 200) as u8, (n % 250) as u8],
            hosts: hosts.iter().map(|h| h.to_string()).collect(),
            filters: BTreeMap::new(),
            made: Vec::new(),
            procs: Vec::new(),
            dir: tempfile::Builder::new().prefix("situ-lab-").tempdir().expect("a temporary directory"),
        };
        if let Err(e) = lab.build() {
            panic!(
                "cannot make the test hosts (network namespaces; this needs root, or CAP_SYS_ADMIN and \
                 CAP_NET_ADMIN, and iproute2: `bash scripts/install-net-tools.sh`): {e}"
            );
        }
        lab
    }

    fn build(&mut self) -> Result<(), String> {
        let sw = self.switch_ns();
        self.add_ns(&sw)?;
        ip(&["-n", &sw, "link", "set", "lo", "up"])?;
        ip(&["-n", &sw, "link", "add", "br0", "type", "bridge"])?;
        ip(&["-n", &sw, "addr", "add", &format!("{}/24", self.switch_addr()), "dev", "br0"])?;
        ip(&["-n", &sw, "link", "set", "br0", "up"])?;
        for (i, host) in self.hosts.clone().iter().enumerate() {
            let ns = self.ns(host);
            self.add_ns(&ns)?;
            let port = format!("v{i}");
            ip(&["-n", &sw, "link", "add", &port, "type", "veth", "peer", "name", "eth0", "netns", &ns])?;
            ip(&["-n", &sw, "link", "set", &port, "master", "br0"])?;
            ip(&["-n", &sw, "link", "set", &port, "up"])?;
            ip(&["-n", &ns, "addr", "add", &format!("{}/24", self.addr(host)), "dev", "eth0"])?;
            ip(&["-n", &ns, "link", "set", "eth0", "up"])?;
            ip(&["-n", &ns, "link", "set", "lo", "up"])?;
        }
        Ok(())
    }

    fn add_ns(&mut self, ns: &str) -> Result<(), String> {
        ip(&["netns", "add", ns])?;
        self.made.push(ns.to_string());
        Ok(())
    }

    fn index(&self, host: &str) -> usize {
        self.hosts.iter().position(|h| h == host).unwrap_or_else(|| panic!("no host `{host}` in this lab"))
    }

    /// The namespace of a host.
    pub fn ns(&self, host: &str) -> String {
        format!("{}{}", self.prefix, self.hosts[self.index(host)])
    }

    fn switch_ns(&self) -> String {
        format!("{}sw", self.prefix)
    }

    /// A host's address.
    pub fn addr(&self, host: &str) -> String {
        let [a, b, c] = self.net;
        format!("{a}.{b}.{c}.{}", self.index(host) + 1)
    }

    /// The switch's address (where a relay listens).
    pub fn switch_addr(&self) -> String {
        let [a, b, c] = self.net;
        format!("{a}.{b}.{c}.254")
    }

    fn subnet(&self) -> String {
        let [a, b, c] = self.net;
        format!("{a}.{b}.{c}.0/24")
    }

    /// The lab's directory (deployments, recordings, the processes' output).
    pub fn dir(&self) -> &Path {
        self.dir.path()
    }

    /// Runs `cmd` in `host` (`ip netns exec`), its standard output and
    /// error to files of the lab (`LABEL.out`, `LABEL.err`).
    pub fn spawn(&mut self, host: &str, label: &str, cmd: Command) -> Pid {
        let ns = self.ns(host);
        self.spawn_in(&ns, label, cmd)
    }

    fn spawn_in(&mut self, ns: &str, label: &str, cmd: Command) -> Pid {
        let out = self.dir().join(format!("{label}.out"));
        let err = self.dir().join(format!("{label}.err"));
        let mut c = Command::new("ip");
        c.args(["netns", "exec", ns]).arg(cmd.get_program()).args(cmd.get_args());
        for (k, v) in cmd.get_envs() {
            match v {
                Some(v) => c.env(k, v),
                None => c.env_remove(k),
            };
        }
        if let Some(d) = cmd.get_current_dir() {
            c.current_dir(d);
        }
        c.stdin(Stdio::null())
            .stdout(std::fs::File::create(&out).expect("the output file"))
            .stderr(std::fs::File::create(&err).expect("the error file"));
        let child = c.spawn().unwrap_or_else(|e| panic!("cannot start `{label}` in {ns}: {e}"));
        self.procs.push(Proc { label: label.to_string(), child, out, err, status: None });
        Pid(self.procs.len() - 1)
    }

    /// SIGKILL: no goodbye (the process is reaped at once).
    pub fn kill9(&mut self, pid: Pid) {
        let p = &mut self.procs[pid.0];
        if p.status.is_none() {
            let _ = p.child.kill();
            p.status = p.child.wait().ok();
        }
    }

    /// Waits for a process to end, at most `timeout`; `None` if it still runs.
    pub fn wait(&mut self, pid: Pid, timeout: Duration) -> Option<ExitStatus> {
        let end = Instant::now() + timeout;
        let p = &mut self.procs[pid.0];
        while p.status.is_none() {
            match p.child.try_wait() {
                Ok(Some(s)) => p.status = Some(s),
                Ok(None) if Instant::now() < end => std::thread::sleep(Duration::from_millis(20)),
                _ => break,
            }
        }
        p.status
    }

    /// Waits for a process to end and says it ended well, with its output
    /// in the message otherwise.
    pub fn expect_success(&mut self, pid: Pid, timeout: Duration) {
        let status = self.wait(pid, timeout);
        if !status.is_some_and(|s| s.success()) {
            panic!(
                "`{}` ended with {status:?} (None: still running after {timeout:?})\n{}",
                self.label(pid),
                self.output(pid)
            );
        }
    }

    /// The operating system's id of a process.
    pub fn os_pid(&self, pid: Pid) -> u32 {
        self.procs[pid.0].child.id()
    }

    pub fn label(&self, pid: Pid) -> &str {
        &self.procs[pid.0].label
    }

    pub fn stdout(&self, pid: Pid) -> String {
        std::fs::read_to_string(&self.procs[pid.0].out).unwrap_or_default()
    }

    pub fn stderr(&self, pid: Pid) -> String {
        std::fs::read_to_string(&self.procs[pid.0].err).unwrap_or_default()
    }

    /// A process's standard output and error, for a failure's message.
    pub fn output(&self, pid: Pid) -> String {
        format!("--- {} stdout:\n{}--- stderr:\n{}", self.label(pid), self.stdout(pid), self.stderr(pid))
    }

    /// Every process's output, for a failure's message.
    pub fn outputs(&self) -> String {
        (0..self.procs.len()).map(|i| self.output(Pid(i))).collect::<Vec<_>>().join("\n")
    }

    /// Waits until `pid`'s standard output holds `text`; false after `timeout`.
    pub fn wait_for_output(&mut self, pid: Pid, text: &str, timeout: Duration) -> bool {
        let end = Instant::now() + timeout;
        while Instant::now() < end {
            if self.stdout(pid).contains(text) {
                return true;
            }
            if self.wait(pid, Duration::ZERO).is_some() {
                return self.stdout(pid).contains(text);
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        false
    }

    /// Cuts `host` off: the switch's end of its veth goes down.
    pub fn partition(&self, host: &str) {
        let port = format!("v{}", self.index(host));
        ip(&["-n", &self.switch_ns(), "link", "set", &port, "down"]).unwrap_or_else(|e| panic!("partition: {e}"));
    }

    /// Joins `host` to the switch again.
    pub fn heal(&self, host: &str) {
        let port = format!("v{}", self.index(host));
        ip(&["-n", &self.switch_ns(), "link", "set", &port, "up"]).unwrap_or_else(|e| panic!("heal: {e}"));
    }

    /// Drops `percent` % of the packets that reach `host` from other hosts
    /// (the relay included), at random (nftables' `numgen random` in the
    /// host's input hook); 0 ends it. Loss on every host is loss on every
    /// link, each way.
    pub fn loss(&mut self, host: &str, percent: u8) {
        assert!(percent <= 100);
        let f = self.filters.entry(host.to_string()).or_default();
        f.loss = percent;
        self.write_filter(host);
    }

    /// Drops every TCP segment that reaches `host` from `from` (`None`
    /// ends it): their TCP links stall, datagrams still pass.
    pub fn drop_tcp_from(&mut self, host: &str, from: Option<&str>) {
        let from = from.map(|f| self.index(f));
        self.filters.entry(host.to_string()).or_default().tcp_from = from;
        self.write_filter(host);
    }

    /// From now on `host` reaches other hosts only through the switch's
    /// address (a relay there): direct packets to other hosts are dropped,
    /// so that no link (Zenoh's gossip finds the others' addresses) goes
    /// round the relay.
    pub fn only_through_switch(&mut self, host: &str) {
        self.filters.entry(host.to_string()).or_default().only_switch = true;
        self.write_filter(host);
    }

    fn write_filter(&self, host: &str) {
        let f = self.filters.get(host).copied().unwrap_or_default();
        let mut out = String::new();
        if f.only_switch {
            out +=
                &format!("    oifname \"eth0\" ip daddr {} ip daddr != {} drop\n", self.subnet(), self.switch_addr());
        }
        // Loss is made where the packets arrive: a packet dropped on its
        // way out of its sender is not lost on the wire (the sender's call
        // fails with EPERM, and TCP sends the segment again at once).
        let mut input = String::new();
        if f.loss > 0 {
            input += &format!("    iifname \"eth0\" numgen random mod 100 < {} drop\n", f.loss);
        }
        if let Some(i) = f.tcp_from {
            input += &format!("    iifname \"eth0\" ip saddr {} meta l4proto tcp drop\n", self.addr(&self.hosts[i]));
        }
        // Made (if missing) then deleted, so that the script works on a
        // host with or without the table; then written anew.
        let script = format!(
            "table inet {TABLE}\ndelete table inet {TABLE}\ntable inet {TABLE} {{\n\
             \x20 chain out {{\n    type filter hook output priority 0; policy accept;\n{out}  }}\n\
             \x20 chain in {{\n    type filter hook input priority 0; policy accept;\n{input}  }}\n}}\n"
        );
        let path = self.dir().join(format!("nft-{host}.conf"));
        std::fs::write(&path, script).expect("the nftables script");
        run(Command::new("ip").args(["netns", "exec", &self.ns(host), "nft", "-f"]).arg(&path))
            .unwrap_or_else(|e| panic!("nftables in `{host}`: {e}"));
    }

    /// The least retransmission timeout of TCP between the lab's
    /// namespaces, the switch's (a relay's sockets) included: the route's
    /// `rto_min` (Linux's default is 200 ms).
    pub fn rto_min(&self, ms: u32) {
        let rto = format!("{ms}ms");
        let subnet = self.subnet();
        let mut places: Vec<(String, &str, String)> =
            self.hosts.iter().map(|h| (self.ns(h), "eth0", self.addr(h))).collect();
        places.push((self.switch_ns(), "br0", self.switch_addr()));
        for (ns, dev, addr) in places {
            ip(&[
                "-n", &ns, "route", "replace", &subnet, "dev", dev, "proto", "kernel", "scope", "link", "src", &addr,
                "rto_min", &rto,
            ])
            .unwrap_or_else(|e| panic!("rto_min in {ns}: {e}"));
        }
    }

    /// The kernel's TCP counters in `host` (`nstat -asz`: absolute values,
    /// zeros too): `TcpRetransSegs`, `TcpExtTCPTimeouts`,
    /// `TcpExtTCPLossProbes`, …
    pub fn tcp_counters(&self, host: &str) -> BTreeMap<String, u64> {
        counters(&self.ns(host))
    }

    /// The kernel's TCP counters of the switch's namespace (a relay's
    /// sockets).
    pub fn switch_tcp_counters(&self) -> BTreeMap<String, u64> {
        counters(&self.switch_ns())
    }

    /// A relay in the switch namespace: one port of the switch's address for
    /// each `(host, port)`, whose streams it passes on after `delay_ms`
    /// (each chunk held that long, the order kept). Waits until it listens.
    pub fn relay(&mut self, delay_ms: u32, targets: &[(&str, u16)], udp_targets: &[(&str, u16)]) -> Relay {
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/faults/relay.py");
        let addr = self.switch_addr();
        let mut ports = BTreeMap::new();
        let mut cmd = Command::new("python3");
        cmd.arg(&script).args(["--listen", &addr, "--delay-ms", &delay_ms.to_string()]);
        for (i, (host, port)) in targets.iter().enumerate() {
            let via = 20000 + i as u16;
            ports.insert((host.to_string(), *port), via);
            cmd.arg(format!("{via}={}:{port}", self.addr(host)));
        }
        let mut udp_ports = BTreeMap::new();
        for (i, (host, port)) in udp_targets.iter().enumerate() {
            let via = 21000 + i as u16;
            udp_ports.insert((host.to_string(), *port), via);
            cmd.arg(format!("udp:{via}={}:{port}", self.addr(host)));
        }
        let sw = self.switch_ns();
        let n = self.procs.len();
        let pid = self.spawn_in(&sw, &format!("relay-{n}"), cmd);
        if !self.wait_for_output(pid, "listening", Duration::from_secs(20)) {
            panic!("the relay did not start\n{}", self.output(pid));
        }
        Relay { pid, ports, udp_ports, addr }
    }
}

/// The kernel's counters of a namespace (`nstat -asz`).
fn counters(ns: &str) -> BTreeMap<String, u64> {
    let out = run(Command::new("ip").args(["netns", "exec", ns, "nstat", "-asz"]))
        .unwrap_or_else(|e| panic!("nstat in {ns}: {e}"));
    out.lines()
        .filter_map(|l| {
            let mut w = l.split_whitespace();
            Some((w.next()?.to_string(), w.next()?.parse().ok()?))
        })
        .collect()
}

impl Drop for Lab {
    fn drop(&mut self) {
        for p in &mut self.procs {
            if p.status.is_none() {
                let _ = p.child.kill();
                let _ = p.child.wait();
            }
        }
        for ns in self.made.iter().rev() {
            if let Err(e) = ip(&["netns", "del", ns]) {
                eprintln!("lab: {e}");
            }
        }
        // SITU_LAB_KEEP=1 keeps the lab's files (the deployment, the
        // recordings, each process's output) of a test that failed.
        if std::thread::panicking() && std::env::var_os("SITU_LAB_KEEP").is_some() {
            let dir = std::mem::replace(&mut self.dir, tempfile::tempdir().expect("a temporary directory"));
            eprintln!("lab: kept {}", dir.keep().display());
        }
    }
}
