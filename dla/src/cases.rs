//! The reactive layer of DLA: navigation learnt by cases (Urdiales et al.
//! 2006).
//!
//! A case is a [`Situation`] (the smallest range seen in each of N sectors
//! around the robot, and the direction to the next subgoal) and the
//! [`Command`] a driver chose in it. A [`CaseBase`] keeps its cases in a k-d
//! tree index over a normalised key: the N ranges divided by the robot's
//! maximum range (each in [0, 1]) followed by the subgoal direction as
//! `(cos, sin)`; the distance between situations is the Euclidean distance
//! between keys. The reactive layer retrieves the nearest case and applies
//! its command; [`CaseBase::learn`] adds a case on line only when it is
//! novel (farther than the novelty threshold from every case kept).
//!
//! The search is exact (to single precision); its cost grows steeply with
//! the number of sectors (the key's dimension): `examples/dla_speed.rs`
//! measures it for 4, 6 and 8 sectors over 100,000 cases. The index is
//! described in `dla/nearest.rs`: static k-d trees split where the keys
//! spread most, with leaves laid out for vector scans, and a small buffer
//! of the latest cases, so that learning on line stays cheap.
//!
//! The training is supervised: [`drive`] is a scripted driver that steers
//! to the freest sector near the subgoal direction and slows near obstacles.
//!
//! A case base is saved as text ([`CaseBase::write`], atomically: a
//! temporary file in the same directory, then a rename):
//!
//! ```text
//! situ-casebase 1
//! sectors 8
//! max_range 4
//! novelty 0.05
//! cases 2
//! c <N ranges (m)> <cos> <sin> <speed> <turn rate>
//! c ...
//! checksum <FNV-1a 64 of every byte above, 16 hex digits>
//! ```
//!
//! Reading checks the format, its version, the sector count (a file of
//! another robot is refused), every number, the count and the checksum,
//! and gives a [`CaseError`] for any damage.

use super::grid::Beam;
use super::nearest::Index;
use situ_sim::geom::wrap_angle;
use std::collections::HashSet;
use std::f64::consts::{PI, TAU};
use std::fmt;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The first word of a case base file.
pub const MAGIC: &str = "situ-casebase";
/// The version of the file format written.
pub const FORMAT_VERSION: u32 = 1;
/// The largest case base file read (bytes).
pub const MAX_FILE_BYTES: u64 = 512 << 20;

/// What the robot perceives, as the cases see it.
#[derive(Debug, Clone, PartialEq)]
pub struct Situation {
    /// The smallest range (m) seen in each sector. Sector `i` of `N` is
    /// centred on the direction `i·2π/N` from the robot's heading (sector 0
    /// ahead, counter-clockwise) and spans `2π/N`.
    pub ranges: Vec<f64>,
    /// The direction to the next subgoal in the robot's frame, `(cos, sin)`.
    pub goal: [f64; 2],
}

impl Situation {
    /// A situation from its ranges and the angle to the subgoal (rad, robot frame).
    pub fn new(ranges: Vec<f64>, goal_angle: f64) -> Self {
        Situation { ranges, goal: [goal_angle.cos(), goal_angle.sin()] }
    }
    /// The angle (robot frame, in (-π, π]) at the centre of sector `i` of `sectors`.
    pub fn sector_angle(i: usize, sectors: usize) -> f64 {
        wrap_angle(i as f64 * TAU / sectors as f64)
    }
    /// The sector of `sectors` containing direction `angle` (robot frame).
    pub fn sector_of(angle: f64, sectors: usize) -> usize {
        let width = TAU / sectors as f64;
        ((angle.rem_euclid(TAU) / width).round() as usize) % sectors
    }
    /// The situation of a scan: per sector the smallest range of its beams,
    /// capped at `max_range` (a sector without beams reads `max_range`).
    pub fn from_scan(beams: &[Beam], sectors: usize, max_range: f64, goal_angle: f64) -> Self {
        let mut ranges = vec![max_range; sectors];
        for b in beams.iter().filter(|b| b.range.is_finite() && b.angle.is_finite()) {
            let s = Self::sector_of(b.angle, sectors);
            ranges[s] = ranges[s].min(b.range.max(0.0));
        }
        Situation::new(ranges, goal_angle)
    }
    /// The angle to the subgoal (rad, robot frame).
    pub fn goal_angle(&self) -> f64 {
        self.goal[1].atan2(self.goal[0])
    }
}

/// A motion command.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    /// Forward speed (m/s).
    pub speed: f64,
    /// Turn rate (rad/s, counter-clockwise).
    pub turn_rate: f64,
}

/// A situation and the command chosen in it.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// What the robot perceived.
    pub situation: Situation,
    /// What the driver did.
    pub command: Command,
}

/// Why a case base could not be used, read or written.
#[derive(Debug)]
pub enum CaseError {
    /// The file could not be read or written.
    Io(std::io::Error),
    /// The file does not start with [`MAGIC`].
    NotACaseBase,
    /// The file has a format version this code does not read.
    UnsupportedVersion(u32),
    /// The file is of a robot with another number of sectors.
    OtherRobot {
        /// Sectors of this case base.
        expected: usize,
        /// Sectors in the file.
        found: usize,
    },
    /// The file is damaged: a line is missing, malformed or out of range.
    Damaged {
        /// The line (1-based) where the damage was found.
        line: usize,
        /// What is wrong there.
        reason: String,
    },
    /// The content does not match its checksum.
    Checksum,
    /// A situation has a number of ranges other than the sectors.
    SectorCount {
        /// Sectors of this case base.
        expected: usize,
        /// Ranges in the situation.
        found: usize,
    },
    /// A situation or command holds a number that is not finite.
    NotFinite,
}

impl fmt::Display for CaseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CaseError::Io(e) => write!(f, "case base: {e}"),
            CaseError::NotACaseBase => write!(f, "not a case base (no `{MAGIC}` header)"),
            CaseError::UnsupportedVersion(v) => {
                write!(f, "case base format version {v} is not supported (this reads {FORMAT_VERSION})")
            }
            CaseError::OtherRobot { expected, found } => {
                write!(f, "case base of another robot: {found} sectors, this robot has {expected}")
            }
            CaseError::Damaged { line, reason } => write!(f, "damaged case base, line {line}: {reason}"),
            CaseError::Checksum => write!(f, "damaged case base: the checksum does not match"),
            CaseError::SectorCount { expected, found } => {
                write!(f, "situation has {found} ranges, the case base {expected} sectors")
            }
            CaseError::NotFinite => write!(f, "situation or command is not finite"),
        }
    }
}

impl std::error::Error for CaseError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            CaseError::Io(e) => Some(e),
            _ => None,
        }
    }
}

impl From<std::io::Error> for CaseError {
    fn from(e: std::io::Error) -> Self {
        CaseError::Io(e)
    }
}

/// A base of cases over situations of `D − 2` sectors (`D` is the
/// dimension of the key: the sectors and the two components of the subgoal
/// direction; e.g. `CaseBase<10>` for 8 sectors).
#[derive(Debug, Clone)]
pub struct CaseBase<const D: usize> {
    max_range: f64,
    novelty: f64,
    cases: Vec<Case>,
    keys: Vec<[f64; D]>,
    /// The single-precision keys held, bit for bit (a case repeating the
    /// key of another is refused).
    held: HashSet<[u32; D]>,
    /// The nearest-neighbour index over the single-precision keys (half
    /// the memory traffic of double precision); ids are case indices.
    index: Index<D>,
}

fn narrow<const D: usize>(key: &[f64; D]) -> [f32; D] {
    std::array::from_fn(|i| key[i] as f32)
}

fn distance<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt()
}

fn damaged(line: usize, reason: &str) -> CaseError {
    CaseError::Damaged { line, reason: reason.to_string() }
}

/// The lines of a file being read, with their numbers and the bytes read.
struct Lines<'a> {
    text: &'a str,
    pos: usize,
    line: usize,
}

impl<'a> Lines<'a> {
    /// The next whole line (without its newline) and its number.
    fn next(&mut self, what: &str) -> Result<(usize, &'a str), CaseError> {
        let rest = &self.text[self.pos..];
        if rest.is_empty() {
            return Err(damaged(self.line + 1, &format!("missing {what}")));
        }
        self.line += 1;
        match rest.find('\n') {
            Some(end) => {
                self.pos += end + 1;
                Ok((self.line, &rest[..end]))
            }
            None => Err(damaged(self.line, "the file ends in the middle of a line")),
        }
    }
    /// The value of the next line, which must read `name value`.
    fn field(&mut self, name: &str) -> Result<(usize, &'a str), CaseError> {
        let (n, l) = self.next(&format!("`{name}`"))?;
        match l.strip_prefix(name).and_then(|v| v.strip_prefix(' ')) {
            Some(v) => Ok((n, v)),
            None => Err(damaged(n, &format!("expected `{name}`"))),
        }
    }
}

/// FNV-1a, 64 bits.
fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

impl<const D: usize> CaseBase<D> {
    /// Number of range sectors of a situation.
    pub const SECTORS: usize = D - 2;

    /// An empty case base for a robot of maximum range `max_range` (m),
    /// learning cases farther than `novelty` (key distance) from the others.
    ///
    /// # Panics
    /// If `D < 3` or `max_range` is not positive and finite.
    pub fn new(max_range: f64, novelty: f64) -> Self {
        assert!(D >= 3, "a situation has at least one sector");
        assert!(max_range.is_finite() && max_range > 0.0, "the maximum range is positive");
        CaseBase {
            max_range,
            novelty,
            cases: Vec::new(),
            keys: Vec::new(),
            held: HashSet::new(),
            index: Index::default(),
        }
    }
    /// The robot's maximum range (m).
    pub fn max_range(&self) -> f64 {
        self.max_range
    }
    /// The novelty threshold of [`CaseBase::learn`].
    pub fn novelty(&self) -> f64 {
        self.novelty
    }
    /// Sets the novelty threshold.
    pub fn set_novelty(&mut self, novelty: f64) {
        self.novelty = novelty;
    }
    /// Number of cases.
    pub fn len(&self) -> usize {
        self.cases.len()
    }
    /// Whether there is no case.
    pub fn is_empty(&self) -> bool {
        self.cases.is_empty()
    }
    /// The cases, in the order they were added.
    pub fn cases(&self) -> &[Case] {
        &self.cases
    }

    /// The key of a situation: ranges over the maximum range (clamped to
    /// [0, 1]), then the subgoal direction.
    pub fn key(&self, s: &Situation) -> Result<[f64; D], CaseError> {
        if s.ranges.len() != Self::SECTORS {
            return Err(CaseError::SectorCount { expected: Self::SECTORS, found: s.ranges.len() });
        }
        let mut k = [0.0; D];
        for (k, &r) in k.iter_mut().zip(&s.ranges) {
            if !r.is_finite() {
                return Err(CaseError::NotFinite);
            }
            *k = (r / self.max_range).clamp(0.0, 1.0);
        }
        if !(s.goal[0].is_finite() && s.goal[1].is_finite()) {
            return Err(CaseError::NotFinite);
        }
        k[D - 2] = s.goal[0];
        k[D - 1] = s.goal[1];
        Ok(k)
    }

    /// The nearest case to a key: its index in [`CaseBase::cases`] and its
    /// distance; `None` when the base is empty. The search runs on keys
    /// rounded to single precision, so between cases whose distances differ
    /// by less than that precision either may be returned; the distance is
    /// that of the case returned, in double precision.
    pub fn nearest_key(&self, key: &[f64; D]) -> Option<(usize, f64)> {
        let i = self.index.nearest(&narrow(key))?;
        Some((i, distance(key, &self.keys[i])))
    }

    /// The nearest case to a situation: its index and its distance.
    pub fn nearest(&self, s: &Situation) -> Result<Option<(usize, f64)>, CaseError> {
        Ok(self.nearest_key(&self.key(s)?))
    }

    /// The command of the nearest case, if any.
    pub fn command(&self, s: &Situation) -> Result<Option<Command>, CaseError> {
        Ok(self.nearest(s)?.map(|(i, _)| self.cases[i].command))
    }

    /// Adds a case, unless one with the same key (to single precision) is
    /// there (then `false`).
    pub fn insert(&mut self, case: Case) -> Result<bool, CaseError> {
        let key = self.key(&case.situation)?;
        if !(case.command.speed.is_finite() && case.command.turn_rate.is_finite()) {
            return Err(CaseError::NotFinite);
        }
        let narrow = narrow(&key);
        // +0.0 for -0.0, so that equal keys have equal bits.
        if !self.held.insert(narrow.map(|k| (k + 0.0).to_bits())) {
            return Ok(false);
        }
        self.index.add(narrow);
        self.keys.push(key);
        self.cases.push(case);
        Ok(true)
    }

    /// Learns a case on line: adds it only when its distance to the
    /// nearest case is above the novelty threshold (or the base is empty).
    /// Whether it was added.
    pub fn learn(&mut self, case: Case) -> Result<bool, CaseError> {
        let key = self.key(&case.situation)?;
        match self.nearest_key(&key) {
            Some((_, d)) if d <= self.novelty => Ok(false),
            _ => self.insert(case),
        }
    }

    /// The case base as the text of its file.
    pub fn to_text(&self) -> String {
        use std::fmt::Write as _;
        let mut s = String::with_capacity(64 + self.cases.len() * (D + 2) * 12);
        let _ = writeln!(s, "{MAGIC} {FORMAT_VERSION}");
        let _ = writeln!(s, "sectors {}", Self::SECTORS);
        let _ = writeln!(s, "max_range {}", self.max_range);
        let _ = writeln!(s, "novelty {}", self.novelty);
        let _ = writeln!(s, "cases {}", self.cases.len());
        for c in &self.cases {
            s.push('c');
            for r in &c.situation.ranges {
                let _ = write!(s, " {r}");
            }
            let [gx, gy] = c.situation.goal;
            let _ = writeln!(s, " {gx} {gy} {} {}", c.command.speed, c.command.turn_rate);
        }
        let sum = fnv1a(s.as_bytes());
        let _ = writeln!(s, "checksum {sum:016x}");
        s
    }

    /// A case base from the text of its file.
    pub fn from_text(text: &str) -> Result<Self, CaseError> {
        let mut r = Lines { text, pos: 0, line: 0 };
        let (n, first) = r.next("header").map_err(|_| CaseError::NotACaseBase)?;
        let mut words = first.split(' ');
        if words.next() != Some(MAGIC) {
            return Err(CaseError::NotACaseBase);
        }
        let version: u32 = words
            .next()
            .and_then(|v| v.parse().ok())
            .filter(|_| words.next().is_none())
            .ok_or_else(|| damaged(n, "bad format version"))?;
        if version != FORMAT_VERSION {
            return Err(CaseError::UnsupportedVersion(version));
        }
        let (n, v) = r.field("sectors")?;
        let sectors: usize = v.parse().map_err(|_| damaged(n, "bad sector count"))?;
        if sectors != Self::SECTORS {
            return Err(CaseError::OtherRobot { expected: Self::SECTORS, found: sectors });
        }
        let (n, v) = r.field("max_range")?;
        let max_range: f64 = v.parse().map_err(|_| damaged(n, "bad maximum range"))?;
        if !(max_range.is_finite() && max_range > 0.0) {
            return Err(damaged(n, "the maximum range is not positive and finite"));
        }
        let (n, v) = r.field("novelty")?;
        let novelty: f64 = v.parse().map_err(|_| damaged(n, "bad novelty threshold"))?;
        if !novelty.is_finite() {
            return Err(damaged(n, "the novelty threshold is not finite"));
        }
        let (n, v) = r.field("cases")?;
        let count: usize = v.parse().map_err(|_| damaged(n, "bad case count"))?;
        let mut base = CaseBase::new(max_range, novelty);
        let mut numbers = [0.0f64; 64];
        let width = D + 2;
        for _ in 0..count {
            let (n, v) = r.field("c")?;
            let mut k = 0;
            for w in v.split(' ') {
                if k == width || k == numbers.len() {
                    return Err(damaged(n, "too many numbers in a case"));
                }
                numbers[k] = w.parse().map_err(|_| damaged(n, "bad number"))?;
                if !numbers[k].is_finite() {
                    return Err(damaged(n, "a number is not finite"));
                }
                k += 1;
            }
            if k != width {
                return Err(damaged(n, "too few numbers in a case"));
            }
            let case = Case {
                situation: Situation { ranges: numbers[..D - 2].to_vec(), goal: [numbers[D - 2], numbers[D - 1]] },
                command: Command { speed: numbers[D], turn_rate: numbers[D + 1] },
            };
            if !base.insert(case)? {
                return Err(damaged(n, "a case repeats another"));
            }
        }
        let body = r.pos;
        let (n, v) = r.field("checksum")?;
        let sum = u64::from_str_radix(v, 16).map_err(|_| damaged(n, "bad checksum"))?;
        if v.len() != 16 || sum != fnv1a(&text.as_bytes()[..body]) {
            return Err(CaseError::Checksum);
        }
        if r.pos < text.len() {
            return Err(damaged(r.line + 1, "text after the checksum"));
        }
        base.index.compact();
        Ok(base)
    }

    /// Reads a case base file (a regular file of at most [`MAX_FILE_BYTES`]).
    /// The file is never modified.
    pub fn read(path: &Path) -> Result<Self, CaseError> {
        let bytes = situ_compiler::loader::read_bounded(path, MAX_FILE_BYTES, "case base")?;
        let text =
            std::str::from_utf8(&bytes).map_err(|_| CaseError::Damaged { line: 0, reason: "not UTF-8 text".into() })?;
        Self::from_text(text)
    }

    /// Writes the case base to `path` atomically: to a temporary file in the
    /// same directory, flushed to disk, then renamed over `path`. On error
    /// `path` is left as it was and the temporary file is removed.
    pub fn write(&self, path: &Path) -> Result<(), CaseError> {
        let text = self.to_text();
        let name = path
            .file_name()
            .ok_or_else(|| CaseError::Io(std::io::Error::new(std::io::ErrorKind::InvalidInput, "no file name")))?;
        let mut tmp_name = std::ffi::OsString::from(".");
        tmp_name.push(name);
        tmp_name.push(format!(".tmp-{}", std::process::id()));
        let tmp: PathBuf = path.with_file_name(tmp_name);
        let result = (|| -> std::io::Result<()> {
            let mut f = std::fs::File::create(&tmp)?;
            f.write_all(text.as_bytes())?;
            f.sync_all()?;
            drop(f);
            std::fs::rename(&tmp, path)
        })();
        if result.is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
        Ok(result?)
    }
}

/// The limits and gains of the scripted driver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriverParams {
    /// Cruise speed (m/s).
    pub max_speed: f64,
    /// Largest turn rate (rad/s).
    pub max_turn_rate: f64,
    /// Turn rate per radian of heading error (1/s).
    pub turn_gain: f64,
    /// A sector closer than this (m) is not steered into; the robot stops
    /// when an obstacle ahead is this close.
    pub safety: f64,
    /// Below this range ahead (m) the robot slows down.
    pub slow_distance: f64,
    /// Weight of a sector's clearance against its alignment with the subgoal.
    pub clearance_weight: f64,
}

impl Default for DriverParams {
    fn default() -> Self {
        DriverParams {
            max_speed: 0.5,
            max_turn_rate: 1.0,
            turn_gain: 1.5,
            safety: 0.3,
            slow_distance: 1.0,
            clearance_weight: 0.5,
        }
    }
}

/// The scripted driver of the supervised training: steers straight at the
/// subgoal when its sector is clear beyond the slow-down distance, else to
/// the sector that best trades alignment with the subgoal against
/// clearance (and a small preference for turning little); slows down as
/// the nearest obstacle ahead (sectors within ±45°, at least the front
/// one) comes closer, and when the turn is large; turns in place towards
/// the freest sector when no sector is clear.
pub fn drive(s: &Situation, max_range: f64, p: &DriverParams) -> Command {
    let n = s.ranges.len();
    if n == 0 {
        return Command { speed: 0.0, turn_rate: 0.0 };
    }
    let goal = s.goal_angle();
    let goal_sector = Situation::sector_of(goal, n);
    let target = if s.ranges[goal_sector] > p.slow_distance.max(p.safety) {
        Some(goal)
    } else {
        (0..n)
            .filter(|&i| s.ranges[i] > p.safety)
            .map(|i| {
                let a = Situation::sector_angle(i, n);
                let clear = (s.ranges[i] / max_range).clamp(0.0, 1.0);
                let score = (a - goal).cos() + p.clearance_weight * clear - 0.1 * a.abs() / PI;
                (score, a)
            })
            .max_by(|x, y| x.0.total_cmp(&y.0))
            .map(|(_, a)| a)
    };
    let Some(target) = target else {
        let freest = (0..n).max_by(|&i, &j| s.ranges[i].total_cmp(&s.ranges[j])).unwrap_or(0);
        let a = Situation::sector_angle(freest, n);
        let turn = if a >= 0.0 { p.max_turn_rate } else { -p.max_turn_rate };
        return Command { speed: 0.0, turn_rate: turn };
    };
    let turn_rate = (p.turn_gain * target).clamp(-p.max_turn_rate, p.max_turn_rate);
    let ahead = (0..n)
        .filter(|&i| i == 0 || Situation::sector_angle(i, n).abs() <= PI / 4.0)
        .map(|i| s.ranges[i])
        .fold(f64::INFINITY, f64::min);
    let span = (p.slow_distance - p.safety).max(1e-9);
    let slow = ((ahead - p.safety) / span).clamp(0.0, 1.0);
    let speed = p.max_speed * slow * target.cos().max(0.0);
    Command { speed, turn_rate }
}
