//! Decoding of messages from CDR, as ROS 2 middlewares send
//! them: a 4-byte encapsulation header (`00 01` little-endian, `00 00`
//! big-endian), then the fields in order with the XCDR1 rules: each
//! primitive aligned to its size (8 at most) from the end of the header,
//! strings as a `u32` length counting the NUL then the bytes, sequences as a
//! `u32` count then the elements, fixed arrays without a count, nested
//! messages inline.
//!
//! One generic walker reads every type: [`Decoder::new`] compiles the
//! registry's definition of a type into a layout once, and
//! [`Decoder::decode`] walks it. It never panics and never allocates more
//! than the input can hold: a count larger than the bytes left is an error.

use crate::expr::{self, Expr, Step};
use crate::msgs::idl::{self, Array, Base};
use crate::msgs::{intern, Registry};
use std::fmt;

/// A decoded value.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Bool(bool),
    /// Every integer type; a `uint64` above `i64::MAX` is a [`Value::Float`].
    Int(i64),
    /// `float32` (exactly, widened) and `float64`.
    Float(f64),
    /// Bytes that are not UTF-8 are replaced by U+FFFD.
    Str(String),
    /// A sequence or a fixed array.
    Array(Vec<Value>),
    /// A message: its fields in the order of the definition.
    Msg(Vec<(&'static str, Value)>),
}

impl Value {
    /// The field `name` of a message.
    pub fn field(&self, name: &str) -> Option<&Value> {
        match self {
            Value::Msg(fields) => fields.iter().find(|(n, _)| *n == name).map(|(_, v)| v),
            _ => None,
        }
    }

    /// Element `i` of an array.
    pub fn index(&self, i: u64) -> Option<&Value> {
        match self {
            Value::Array(items) => usize::try_from(i).ok().and_then(|i| items.get(i)),
            _ => None,
        }
    }

    /// The value at a field path written as in the map (`status[0].level`).
    pub fn at(&self, path: &str) -> Option<&Value> {
        match expr::parse(path).ok()? {
            Expr::Path(steps, _) => steps.iter().try_fold(self, |v, s| match s {
                Step::Field(name, _) => v.field(name),
                Step::Index(i, _) => v.index(*i),
            }),
            _ => None,
        }
    }
}

/// A message that does not decode as its type.
#[derive(Debug, Clone, PartialEq)]
pub struct DecodeError {
    /// The full name of the type (`sensor_msgs/msg/LaserScan`).
    pub ty: &'static str,
    pub message: String,
}

impl fmt::Display for DecodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let short = self.ty.rsplit('/').next().unwrap_or(self.ty);
        write!(f, "{short}: {}", self.message)
    }
}

impl std::error::Error for DecodeError {}

/// A primitive as it is on the wire.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Prim {
    Bool,
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
    String,
}

impl Prim {
    /// Its name in `.msg` files (`byte` and `char` are `uint8` on the
    /// wire, and named so in errors).
    fn name(self) -> &'static str {
        match self {
            Prim::Bool => "bool",
            Prim::I8 => "int8",
            Prim::U8 => "uint8",
            Prim::I16 => "int16",
            Prim::U16 => "uint16",
            Prim::I32 => "int32",
            Prim::U32 => "uint32",
            Prim::I64 => "int64",
            Prim::U64 => "uint64",
            Prim::F32 => "float32",
            Prim::F64 => "float64",
            Prim::String => "string",
        }
    }

    /// Its size and alignment; a string's is its length's.
    fn size(self) -> usize {
        match self {
            Prim::Bool | Prim::I8 | Prim::U8 => 1,
            Prim::I16 | Prim::U16 => 2,
            Prim::I32 | Prim::U32 | Prim::F32 | Prim::String => 4,
            Prim::I64 | Prim::U64 | Prim::F64 => 8,
        }
    }
}

#[derive(Debug, Clone)]
enum Kind {
    Prim(Prim),
    Msg(Box<Layout>),
    Seq(Box<Kind>),
    Fixed(Box<Kind>, usize),
}

impl Kind {
    /// The fewest bytes one value takes (alignment left out), at least 1:
    /// the bound on a sequence's count.
    fn min_size(&self) -> usize {
        match self {
            Kind::Prim(p) => p.size(),
            Kind::Msg(l) => l.fields.iter().map(|(_, k)| k.min_size()).fold(0usize, usize::saturating_add).max(1),
            Kind::Seq(_) => 4,
            Kind::Fixed(k, n) => k.min_size().saturating_mul(*n).max(1),
        }
    }
}

/// The fields of one message type, as the walker reads them.
#[derive(Debug, Clone)]
struct Layout {
    name: &'static str,
    fields: Vec<(&'static str, Kind)>,
}

/// The layout of the message `msg` (a full name); `None` if it or a type
/// it uses is not defined, or uses `wstring` (whose encoding middlewares
/// do not agree on). Recursive definitions cannot be written in `.msg`
/// files; `depth` bounds them anyway.
fn layout(reg: &Registry, msg: &str, depth: usize) -> Option<Layout> {
    let def = reg.def(msg)?;
    if depth > 64 {
        return None;
    }
    let mut fields = Vec::with_capacity(def.fields.len());
    for f in &def.fields {
        let elem = match &f.ty.base {
            Base::Prim(p) => Kind::Prim(wire(*p)?),
            Base::Msg(m) => Kind::Msg(Box::new(layout(reg, m, depth + 1)?)),
        };
        let k = match f.ty.array {
            Array::Not => elem,
            Array::Fixed(n) => Kind::Fixed(Box::new(elem), n),
            Array::Unbounded | Array::Bounded(_) => Kind::Seq(Box::new(elem)),
        };
        fields.push((intern(&f.name), k));
    }
    Some(Layout { name: intern(&def.name), fields })
}

/// The wire primitive of a `.msg` primitive.
fn wire(p: idl::Prim) -> Option<Prim> {
    Some(match p {
        idl::Prim::Bool => Prim::Bool,
        idl::Prim::I8 => Prim::I8,
        idl::Prim::Byte | idl::Prim::Char | idl::Prim::U8 => Prim::U8,
        idl::Prim::I16 => Prim::I16,
        idl::Prim::U16 => Prim::U16,
        idl::Prim::I32 => Prim::I32,
        idl::Prim::U32 => Prim::U32,
        idl::Prim::I64 => Prim::I64,
        idl::Prim::U64 => Prim::U64,
        idl::Prim::F32 => Prim::F32,
        idl::Prim::F64 => Prim::F64,
        idl::Prim::String(_) => Prim::String,
        idl::Prim::WString(_) => return None,
    })
}

/// The decoder of one message type.
#[derive(Debug, Clone)]
pub struct Decoder {
    layout: Layout,
}

/// The largest sequence count decoded, whatever the input's size.
pub const MAX_COUNT: u32 = 1 << 26;

impl Decoder {
    /// The decoder of `ty` (`pkg/msg/Name` or `pkg/Name`) as `reg` defines
    /// it; `None` if the type or a type it uses is not defined (or has a
    /// `wstring`).
    pub fn new(reg: &Registry, ty: &str) -> Option<Decoder> {
        layout(reg, reg.lookup(ty)?, 0).map(|layout| Decoder { layout })
    }

    /// The full name of the type it decodes.
    pub fn type_name(&self) -> &'static str {
        self.layout.name
    }

    /// Decodes one serialized message, header included. Bytes after the
    /// message (the padding middlewares add) are ignored.
    pub fn decode(&self, cdr: &[u8]) -> Result<Value, DecodeError> {
        let fail = |message: String| DecodeError { ty: self.layout.name, message };
        let Some((header, body)) = cdr.split_first_chunk::<4>() else {
            return Err(fail(format!("{} bytes, too short for the 4-byte encapsulation header", cdr.len())));
        };
        let little = match (header[0], header[1]) {
            (0, 0) => false,
            (0, 1) => true,
            (a, b) => {
                return Err(fail(format!(
                    "encapsulation {a:02x} {b:02x} is not plain CDR (00 00 big-endian, 00 01 little-endian)"
                )))
            }
        };
        let mut r = Reader { buf: body, pos: 0, little };
        r.msg(&self.layout).map_err(|e| fail(e.to_string()))
    }
}

/// What went wrong, and the field path where (built on the way out).
#[derive(Debug)]
struct Raw {
    path: String,
    what: What,
}

#[derive(Debug)]
enum What {
    Short { prim: &'static str, need: usize, left: usize },
    SeqTooLong { count: u32, left: usize },
    StrTooLong { len: u32, left: usize },
    NoNul,
}

impl fmt::Display for Raw {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let p = &self.path;
        match self.what {
            What::Short { prim, need, left } => {
                write!(f, "`{p}` ({prim}) needs {need} bytes, {left} left: the message is cut short")
            }
            What::SeqTooLong { count, left } => {
                write!(f, "sequence `{p}` claims {count} elements, {left} bytes left")
            }
            What::StrTooLong { len, left } => write!(f, "string `{p}` claims {len} bytes, {left} left"),
            What::NoNul => write!(f, "string `{p}` does not end with a NUL byte"),
        }
    }
}

fn raw(what: What) -> Raw {
    Raw { path: String::new(), what }
}

/// Prefixes the error's path with `step` (a field name or `[i]`).
fn within(step: impl fmt::Display) -> impl FnOnce(Raw) -> Raw {
    move |mut e| {
        e.path = if e.path.is_empty() {
            step.to_string()
        } else if e.path.starts_with('[') {
            format!("{step}{}", e.path)
        } else {
            format!("{step}.{}", e.path)
        };
        e
    }
}

fn reversed<const N: usize>(mut bytes: [u8; N]) -> [u8; N] {
    bytes.reverse();
    bytes
}

struct Reader<'a> {
    buf: &'a [u8],
    pos: usize,
    little: bool,
}

impl Reader<'_> {
    fn left(&self) -> usize {
        self.buf.len().saturating_sub(self.pos)
    }

    /// `N` bytes of a primitive of size `N`, aligned to `N`.
    fn take<const N: usize>(&mut self, prim: Prim) -> Result<[u8; N], Raw> {
        let pad = (N - self.pos % N) % N;
        let short = || raw(What::Short { prim: prim.name(), need: pad + N, left: self.left() });
        let start = self.pos.checked_add(pad).ok_or_else(short)?;
        let bytes: [u8; N] = self.buf.get(start..).and_then(|b| b.first_chunk::<N>()).copied().ok_or_else(short)?;
        self.pos = start + N;
        Ok(if self.little { bytes } else { reversed(bytes) })
    }

    fn u32(&mut self, prim: Prim) -> Result<u32, Raw> {
        self.take::<4>(prim).map(u32::from_le_bytes)
    }

    fn prim(&mut self, p: Prim) -> Result<Value, Raw> {
        Ok(match p {
            Prim::Bool => Value::Bool(self.take::<1>(p)?[0] != 0),
            Prim::I8 => Value::Int(i8::from_le_bytes(self.take(p)?).into()),
            Prim::U8 => Value::Int(self.take::<1>(p)?[0].into()),
            Prim::I16 => Value::Int(i16::from_le_bytes(self.take(p)?).into()),
            Prim::U16 => Value::Int(u16::from_le_bytes(self.take(p)?).into()),
            Prim::I32 => Value::Int(i32::from_le_bytes(self.take(p)?).into()),
            Prim::U32 => Value::Int(self.u32(p)?.into()),
            Prim::I64 => Value::Int(i64::from_le_bytes(self.take(p)?)),
            Prim::U64 => {
                let u = u64::from_le_bytes(self.take(p)?);
                i64::try_from(u).map_or(Value::Float(u as f64), Value::Int)
            }
            Prim::F32 => Value::Float(f32::from_le_bytes(self.take(p)?).into()),
            Prim::F64 => Value::Float(f64::from_le_bytes(self.take(p)?)),
            Prim::String => {
                let len = self.u32(p)?;
                let n = len as usize;
                let Some(bytes) = self.buf.get(self.pos..).and_then(|b| b.get(..n)) else {
                    return Err(raw(What::StrTooLong { len, left: self.left() }));
                };
                self.pos += n;
                // A length of 0 is not what a middleware sends; read it as "".
                let text = match bytes.split_last() {
                    None => &[][..],
                    Some((0, text)) => text,
                    Some(_) => return Err(raw(What::NoNul)),
                };
                Value::Str(String::from_utf8_lossy(text).into_owned())
            }
        })
    }

    fn msg(&mut self, l: &Layout) -> Result<Value, Raw> {
        if l.fields.is_empty() {
            // The DDS type of an empty ROS 2 message has one octet,
            // `structure_needs_at_least_one_member`.
            self.take::<1>(Prim::U8)?;
            return Ok(Value::Msg(Vec::new()));
        }
        let mut out = Vec::with_capacity(l.fields.len());
        for (name, k) in &l.fields {
            out.push((*name, self.value(k).map_err(within(name))?));
        }
        Ok(Value::Msg(out))
    }

    fn value(&mut self, k: &Kind) -> Result<Value, Raw> {
        match k {
            Kind::Prim(p) => self.prim(*p),
            Kind::Msg(l) => self.msg(l),
            Kind::Fixed(elem, n) => self.elements(elem, *n),
            Kind::Seq(elem) => {
                let count = self.u32(Prim::U32)?;
                let left = self.left();
                if count > MAX_COUNT || (count as usize).saturating_mul(elem.min_size()) > left {
                    return Err(raw(What::SeqTooLong { count, left }));
                }
                self.elements(elem, count as usize)
            }
        }
    }

    fn elements(&mut self, elem: &Kind, n: usize) -> Result<Value, Raw> {
        let mut out = Vec::with_capacity(n.min(self.left()));
        for i in 0..n {
            out.push(self.value(elem).map_err(|e| within(format!("[{i}]"))(e))?);
        }
        Ok(Value::Array(out))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn decoder(ty: &str) -> Option<Decoder> {
        Decoder::new(&Registry::carried(), ty)
    }

    fn names() -> Vec<String> {
        Registry::carried().names().map(str::to_string).collect()
    }

    /// A test encoder: writes a random valid message of a layout and
    /// returns the value it wrote.
    struct Writer {
        body: Vec<u8>,
        little: bool,
        seed: u64,
    }

    impl Writer {
        fn next(&mut self) -> u64 {
            // xorshift64*
            self.seed ^= self.seed >> 12;
            self.seed ^= self.seed << 25;
            self.seed ^= self.seed >> 27;
            self.seed.wrapping_mul(0x2545_f491_4f6c_dd1d)
        }

        fn put(&mut self, le: &[u8]) {
            while !self.body.len().is_multiple_of(le.len()) {
                self.body.push(0);
            }
            if self.little {
                self.body.extend_from_slice(le);
            } else {
                self.body.extend(le.iter().rev());
            }
        }

        fn prim(&mut self, p: Prim) -> Value {
            let r = self.next();
            let (le, v): (Vec<u8>, Value) = match p {
                Prim::Bool => (vec![(r & 1) as u8], Value::Bool(r & 1 == 1)),
                Prim::I8 => (vec![r as u8], Value::Int((r as u8 as i8).into())),
                Prim::U8 => (vec![r as u8], Value::Int((r as u8).into())),
                Prim::I16 => ((r as i16).to_le_bytes().into(), Value::Int((r as i16).into())),
                Prim::U16 => ((r as u16).to_le_bytes().into(), Value::Int((r as u16).into())),
                Prim::I32 => ((r as i32).to_le_bytes().into(), Value::Int((r as i32).into())),
                Prim::U32 => ((r as u32).to_le_bytes().into(), Value::Int((r as u32).into())),
                Prim::I64 => ((r as i64).to_le_bytes().into(), Value::Int(r as i64)),
                Prim::U64 => ((r >> 1).to_le_bytes().into(), Value::Int((r >> 1) as i64)),
                Prim::F32 => {
                    let f = (r % 10_000) as f32 / 7.0;
                    (f.to_le_bytes().into(), Value::Float(f.into()))
                }
                Prim::F64 => {
                    let f = (r % 10_000) as f64 / 7.0 - 100.0;
                    (f.to_le_bytes().into(), Value::Float(f))
                }
                Prim::String => {
                    let text: String = (0..r % 6).map(|i| char::from(b'a' + ((r >> (i * 5)) % 26) as u8)).collect();
                    self.put(&(text.len() as u32 + 1).to_le_bytes());
                    self.body.extend_from_slice(text.as_bytes());
                    self.body.push(0);
                    return Value::Str(text);
                }
            };
            self.put(&le);
            v
        }

        fn value(&mut self, k: &Kind) -> Value {
            match k {
                Kind::Prim(p) => self.prim(*p),
                Kind::Msg(l) => self.msg(l),
                Kind::Fixed(e, n) => Value::Array((0..*n).map(|_| self.value(e)).collect()),
                Kind::Seq(e) => {
                    let n = self.next() % 4;
                    self.put(&(n as u32).to_le_bytes());
                    Value::Array((0..n).map(|_| self.value(e)).collect())
                }
            }
        }

        fn msg(&mut self, l: &Layout) -> Value {
            if l.fields.is_empty() {
                self.body.push(0);
            }
            Value::Msg(l.fields.iter().map(|(n, k)| (*n, self.value(k))).collect())
        }
    }

    /// A random valid message of `ty`: its CDR bytes and its value.
    fn sample(ty: &str, seed: u64, little: bool) -> (Vec<u8>, Value) {
        let d = decoder(ty).unwrap();
        let mut w = Writer { body: Vec::new(), little, seed: seed | 1 };
        let v = w.msg(&d.layout);
        let mut bytes = vec![0, u8::from(little), 0, 0];
        bytes.extend(w.body);
        (bytes, v)
    }

    #[test]
    fn every_carried_type_has_a_decoder() {
        for name in names() {
            let d = decoder(&name).unwrap_or_else(|| panic!("{name}"));
            assert_eq!(d.type_name(), name);
        }
        assert!(decoder("sensor_msgs/LaserScan").is_some());
        assert!(decoder("sensor_msgs/msg/Nothing").is_none());
    }

    /// A LaserScan written byte by byte, little-endian.
    fn scan_le(ranges: &[f32]) -> Vec<u8> {
        let mut b = vec![0, 1, 0, 0];
        b.extend(7i32.to_le_bytes()); // stamp.sec
        b.extend(9u32.to_le_bytes()); // stamp.nanosec
        b.extend(6u32.to_le_bytes());
        b.extend(b"laser\0");
        b.extend([0, 0]); // pad to 4
        for f in [-1.5f32, 1.5, 0.01, 0.0, 0.1, 0.05, 30.0] {
            b.extend(f.to_le_bytes());
        }
        b.extend((ranges.len() as u32).to_le_bytes());
        for r in ranges {
            b.extend(r.to_le_bytes());
        }
        b.extend(0u32.to_le_bytes()); // no intensities
        b
    }

    #[test]
    fn laser_scan_by_hand() {
        let v = decoder("sensor_msgs/msg/LaserScan").unwrap().decode(&scan_le(&[0.25, 2.0, f32::INFINITY])).unwrap();
        assert_eq!(v.at("header.stamp.sec"), Some(&Value::Int(7)));
        assert_eq!(v.at("header.stamp.nanosec"), Some(&Value::Int(9)));
        assert_eq!(v.at("header.frame_id"), Some(&Value::Str("laser".into())));
        assert_eq!(v.at("angle_increment"), Some(&Value::Float(0.01f32.into())));
        assert_eq!(v.at("ranges[0]"), Some(&Value::Float(0.25)));
        assert_eq!(v.at("ranges[2]"), Some(&Value::Float(f64::INFINITY)));
        assert_eq!(v.at("intensities"), Some(&Value::Array(vec![])));
    }

    #[test]
    fn big_endian_and_alignment_of_doubles() {
        // Odometry: a float64 after a string is aligned to 8 from the body.
        let mut b = vec![0, 0, 0, 0];
        b.extend(1i32.to_be_bytes());
        b.extend(2u32.to_be_bytes());
        b.extend(4u32.to_be_bytes());
        b.extend(b"odo\0");
        b.extend(3u32.to_be_bytes());
        b.extend(b"bs\0");
        b.push(0); // 16 + 4 + 3 = 23: pad to 24, then float64
        for i in 0..(3 + 4 + 36 + 6 + 36) {
            b.extend(f64::from(i).to_be_bytes());
        }
        let v = decoder("nav_msgs/Odometry").unwrap().decode(&b).unwrap();
        assert_eq!(v.at("child_frame_id"), Some(&Value::Str("bs".into())));
        assert_eq!(v.at("pose.pose.position.x"), Some(&Value::Float(0.0)));
        assert_eq!(v.at("pose.covariance[35]"), Some(&Value::Float(42.0)));
        assert_eq!(v.at("twist.twist.linear.x"), Some(&Value::Float(43.0)));
        assert_eq!(v.at("twist.covariance[35]"), Some(&Value::Float(84.0)));
    }

    #[test]
    fn errors_are_clear() {
        let d = decoder("sensor_msgs/msg/LaserScan").unwrap();
        let mut b = scan_le(&[]);
        let at = b.len() - 8;
        b.truncate(at);
        b.extend(4_000_000_000u32.to_le_bytes());
        b.extend([0; 12]);
        assert_eq!(
            d.decode(&b).unwrap_err().to_string(),
            "LaserScan: sequence `ranges` claims 4000000000 elements, 12 bytes left"
        );
        assert!(d.decode(&b[..3]).unwrap_err().to_string().contains("too short"));
        assert!(d.decode(&[0, 7, 0, 0]).unwrap_err().to_string().contains("encapsulation 00 07"));
        let short = d.decode(&scan_le(&[1.0])[..30]).unwrap_err().to_string();
        assert!(short.contains("`angle_max` (float32)"), "{short}");

        // A nested path: status[0].values[0].key claims too many bytes.
        let mut b = vec![0, 1, 0, 0];
        b.extend([0; 8]); // stamp
        b.extend(1u32.to_le_bytes()); // frame_id: "" (its NUL)
        b.extend([0, 0, 0, 0]); // the NUL and padding
        b.extend(1u32.to_le_bytes()); // one status
        b.extend([2, 0, 0, 0]); // level, padding
        for _ in 0..3 {
            b.extend(1u32.to_le_bytes()); // name, message, hardware_id: ""
            b.extend([0, 0, 0, 0]);
        }
        b.extend(1u32.to_le_bytes()); // one key value
        b.extend(99u32.to_le_bytes()); // key claims 99 bytes
        b.extend([0; 4]);
        let e = decoder("diagnostic_msgs/DiagnosticArray").unwrap().decode(&b).unwrap_err();
        assert_eq!(e.to_string(), "DiagnosticArray: string `status[0].values[0].key` claims 99 bytes, 4 left");
    }

    #[test]
    fn empty_and_bool() {
        let d = decoder("std_msgs/msg/Empty").unwrap();
        assert_eq!(d.decode(&[0, 1, 0, 0, 0]), Ok(Value::Msg(vec![])));
        assert!(d.decode(&[0, 1, 0, 0]).is_err());
        let b = decoder("std_msgs/Bool").unwrap();
        assert_eq!(b.decode(&[0, 1, 0, 0, 1, 0, 0, 0]).unwrap().at("data"), Some(&Value::Bool(true)));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// Every type: a random valid message decodes to what was written,
        /// in both byte orders.
        #[test]
        fn round_trip(seed in any::<u64>(), little in any::<bool>()) {
            for ty in names() {
                let (bytes, v) = sample(&ty, seed, little);
                prop_assert_eq!(decoder(&ty).unwrap().decode(&bytes), Ok(v), "{}", ty);
            }
        }

        /// Every type: mutated messages and random bytes never panic, and a
        /// decoded message never holds more values than the input has bytes.
        #[test]
        fn mutated_never_panics(
            seed in any::<u64>(),
            edits in proptest::collection::vec((any::<usize>(), any::<u8>(), 0u8..4), 1..8),
            noise in proptest::collection::vec(any::<u8>(), 0..64),
        ) {
            for ty in names() {
                let d = decoder(&ty).unwrap();
                let (mut bytes, _) = sample(&ty, seed, seed & 1 == 0);
                for (at, byte, op) in &edits {
                    let at = at % (bytes.len() + 1);
                    match op {
                        0 if at < bytes.len() => bytes[at] = *byte,
                        1 => bytes.insert(at, *byte),
                        2 => bytes.truncate(at),
                        _ => if at + 4 <= bytes.len() { bytes[at..at + 4].copy_from_slice(&[0xff, 0xff, 0xff, *byte]) },
                    }
                }
                if let Ok(v) = d.decode(&bytes) {
                    prop_assert!(count(&v) <= bytes.len() + 64);
                }
                let _ = d.decode(&noise);
                let mut framed = vec![0, 1, 0, 0];
                framed.extend(&noise);
                let _ = d.decode(&framed);
            }
        }
    }

    /// The number of leaves of a value.
    fn count(v: &Value) -> usize {
        match v {
            Value::Array(items) => items.iter().map(count).sum(),
            Value::Msg(fields) => fields.iter().map(|(_, v)| count(v)).sum::<usize>().max(1),
            _ => 1,
        }
    }
}
