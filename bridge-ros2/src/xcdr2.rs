//! XCDR2 (DDS-XTypes 1.3, §7.4.3) read into the XCDR1 the map's decoder
//! reads, for the types of the registry: a sample in `00 06`/`00 07`
//! (final types) or `00 08`/`00 09` (appendable: delimited) becomes the
//! same message in plain little-endian CDR (`00 01`).
//!
//! What differs from XCDR1 for these types: 8-byte primitives align to 4; a
//! sequence or array of strings or of structures starts with a DHEADER (a
//! `u32` byte length); in the delimited form, every structure does too
//! (and may end with members a newer definition added, skipped here). The
//! parameter-list form (`00 0a`/`00 0b`, mutable types) is not read.
//!
//! Bounded like the decoder: nothing is allocated beyond what the input
//! holds, and a length or count past its end is an error.

use situ_ros2_map::msgs::idl::{Array, Base, Prim, TypeRef};
use situ_ros2_map::msgs::{intern, Registry};

/// Whether `cdr`'s encapsulation is one [`to_xcdr1`] reads.
pub fn is_xcdr2(cdr: &[u8]) -> bool {
    matches!(cdr, [0, 6..=9, ..])
}

/// Why a sample is not read as XCDR2.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Xcdr2Error {
    #[error("{len} bytes, too short for the 4-byte encapsulation header")]
    TooShort { len: usize },
    #[error("encapsulation {0:02x} {1:02x} is not XCDR2")]
    NotXcdr2(u8, u8),
    #[error("`{0}` is not a message type situ knows (or it has a `wstring`)")]
    UnknownType(&'static str),
    #[error("{needed} bytes needed at {at}, {left} left")]
    Truncated { needed: usize, at: usize, left: usize },
    #[error("a DHEADER of {len} bytes, {left} left")]
    Dheader { len: usize, left: usize },
    #[error("`{0}` runs past its DHEADER")]
    PastDheader(&'static str),
    #[error("{count} elements, {left} bytes left")]
    Elements { count: usize, left: usize },
    #[error("a sequence runs past its DHEADER")]
    SequencePastDheader,
}

/// The message `ty` (a full name of `reg`) of the XCDR2 sample `cdr` (its
/// encapsulation header included), as plain little-endian CDR.
pub fn to_xcdr1(reg: &Registry, ty: &str, cdr: &[u8]) -> Result<Vec<u8>, Xcdr2Error> {
    let Some((header, body)) = cdr.split_first_chunk::<4>() else {
        return Err(Xcdr2Error::TooShort { len: cdr.len() });
    };
    let (little, delimited) = match (header[0], header[1]) {
        (0, 6) => (false, false),
        (0, 7) => (true, false),
        (0, 8) => (false, true),
        (0, 9) => (true, true),
        (a, b) => return Err(Xcdr2Error::NotXcdr2(a, b)),
    };
    let mut t = Transcoder { reg, input: body, pos: 0, little, delimited, out: vec![0, 1, 0, 0] };
    t.msg(ty, 0)?;
    Ok(t.out)
}

struct Transcoder<'a> {
    reg: &'a Registry,
    input: &'a [u8],
    pos: usize,
    little: bool,
    delimited: bool,
    out: Vec<u8>,
}

/// The size of a primitive; a string's length is 4.
fn width(p: Prim) -> usize {
    match p {
        Prim::Bool | Prim::Byte | Prim::Char | Prim::I8 | Prim::U8 => 1,
        Prim::I16 | Prim::U16 => 2,
        Prim::I64 | Prim::U64 | Prim::F64 => 8,
        _ => 4,
    }
}

impl Transcoder<'_> {
    /// `n` bytes aligned to `align` (at most 4 in XCDR2).
    fn read(&mut self, n: usize, align: usize) -> Result<&[u8], Xcdr2Error> {
        let align = align.min(4);
        let start = self.pos.next_multiple_of(align);
        let bytes = self.input.get(start..).and_then(|b| b.get(..n));
        let bytes = bytes.ok_or(Xcdr2Error::Truncated { needed: n, at: start, left: self.input.len() - self.pos })?;
        self.pos = start + n;
        Ok(bytes)
    }

    fn u32(&mut self) -> Result<u32, Xcdr2Error> {
        let little = self.little;
        let b = self.read(4, 4)?;
        let b = [b[0], b[1], b[2], b[3]];
        Ok(if little { u32::from_le_bytes(b) } else { u32::from_be_bytes(b) })
    }

    /// Writes `bytes` (as read, of `width` bytes each) little-endian,
    /// aligned to `width` from the start of the body (XCDR1).
    fn write(&mut self, bytes: &[u8], width: usize) {
        let at = (self.out.len() - 4).next_multiple_of(width) + 4;
        self.out.resize(at, 0);
        for chunk in bytes.chunks(width) {
            if self.little {
                self.out.extend_from_slice(chunk);
            } else {
                self.out.extend(chunk.iter().rev());
            }
        }
    }

    fn write_u32(&mut self, v: u32) {
        let at = (self.out.len() - 4).next_multiple_of(4) + 4;
        self.out.resize(at, 0);
        self.out.extend(v.to_le_bytes());
    }

    /// A DHEADER: the end of what it delimits.
    fn dheader(&mut self) -> Result<usize, Xcdr2Error> {
        let len = self.u32()? as usize;
        let end = self.pos.checked_add(len).filter(|&e| e <= self.input.len());
        end.ok_or(Xcdr2Error::Dheader { len, left: self.input.len() - self.pos })
    }

    fn msg(&mut self, ty: &str, depth: usize) -> Result<(), Xcdr2Error> {
        let end = if self.delimited { Some(self.dheader()?) } else { None };
        let reg = self.reg;
        let def = reg.def(ty).filter(|_| depth <= 64).ok_or_else(|| Xcdr2Error::UnknownType(intern(ty)))?;
        if def.fields.is_empty() {
            // The DDS type of an empty ROS 2 message has one octet.
            let octet = self.read(1, 1)?.to_vec();
            self.write(&octet, 1);
        }
        for f in &def.fields {
            self.field(&f.ty, depth).map_err(|e| match e {
                Xcdr2Error::UnknownType(_) if matches!(f.ty.base, Base::Prim(_)) => Xcdr2Error::UnknownType(intern(ty)),
                e => e,
            })?;
        }
        if let Some(end) = end {
            if self.pos > end {
                return Err(Xcdr2Error::PastDheader(intern(ty)));
            }
            self.pos = end; // members a newer definition appended
        }
        Ok(())
    }

    fn elem(&mut self, base: &Base, depth: usize) -> Result<(), Xcdr2Error> {
        match base {
            Base::Prim(Prim::WString(_)) => Err(Xcdr2Error::UnknownType("wstring")),
            Base::Prim(Prim::String(_)) => {
                let len = self.u32()?;
                self.write_u32(len);
                let bytes = self.read(len as usize, 1)?.to_vec();
                self.out.extend(bytes);
                Ok(())
            }
            Base::Prim(p) => {
                let w = width(*p);
                let bytes = self.read(w, w)?.to_vec();
                self.write(&bytes, w);
                Ok(())
            }
            Base::Msg(m) => self.msg(m, depth + 1),
        }
    }

    fn field(&mut self, ty: &TypeRef, depth: usize) -> Result<(), Xcdr2Error> {
        let size = match ty.array {
            Array::Not => return self.elem(&ty.base, depth),
            Array::Fixed(n) => Some(n),
            Array::Unbounded | Array::Bounded(_) => None,
        };
        let plain = matches!(ty.base, Base::Prim(p) if !p.is_string());
        let end = if plain { None } else { Some(self.dheader()?) };
        let count = match size {
            Some(n) => n,
            None => {
                let count = self.u32()?;
                self.write_u32(count);
                count as usize
            }
        };
        if count > self.input.len() - self.pos {
            return Err(Xcdr2Error::Elements { count, left: self.input.len() - self.pos });
        }
        match &ty.base {
            // Nothing, not even the padding before the elements.
            _ if count == 0 => {}
            Base::Prim(p) if plain => {
                // A run of primitives: one read, one write.
                let w = width(*p);
                let bytes = self.read(w * count, w)?.to_vec();
                self.write(&bytes, w);
            }
            base => {
                for _ in 0..count {
                    self.elem(base, depth)?;
                }
            }
        }
        if let Some(end) = end {
            if self.pos > end {
                return Err(Xcdr2Error::SequencePastDheader);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn to_xcdr1(ty: &str, cdr: &[u8]) -> Result<Vec<u8>, Xcdr2Error> {
        super::to_xcdr1(&Registry::carried(), ty, cdr)
    }

    #[test]
    fn an_appendable_point_loses_its_dheader_and_its_padding() {
        // Point { x: 1.0, y: 2.0, z: 3.0 }, appendable, little-endian, with
        // 4 bytes of a member a newer definition added.
        let mut v2 = vec![0, 9, 0, 0];
        v2.extend(28u32.to_le_bytes());
        for x in [1.0f64, 2.0, 3.0] {
            v2.extend(x.to_le_bytes());
        }
        v2.extend([0xaa; 4]);
        let v1 = to_xcdr1("geometry_msgs/msg/Point", &v2).unwrap();
        let mut expected = vec![0, 1, 0, 0];
        for x in [1.0f64, 2.0, 3.0] {
            expected.extend(x.to_le_bytes());
        }
        assert_eq!(v1, expected);
    }

    #[test]
    fn lengths_past_the_end_are_errors() {
        let mut v2 = vec![0, 9, 0, 0];
        v2.extend(u32::MAX.to_le_bytes());
        let e = to_xcdr1("geometry_msgs/msg/Point", &v2).unwrap_err();
        assert!(e.to_string().contains("DHEADER of 4294967295 bytes"), "{e}");
        let mut v2 = vec![0, 7, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0];
        v2.extend(4_000_000_000u32.to_le_bytes());
        assert!(to_xcdr1("diagnostic_msgs/msg/DiagnosticArray", &v2).is_err());
        assert!(to_xcdr1("std_msgs/msg/Bool", &[0, 7]).is_err());
        assert!(to_xcdr1("std_msgs/msg/Bool", &[0, 1, 0, 0, 1])
            .unwrap_err()
            .to_string()
            .contains("00 01 is not XCDR2"));
    }

    #[test]
    fn no_input_panics_or_grows_more_than_the_alignment_it_adds() {
        // A small xorshift: the same inputs every run.
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let reg = Registry::carried();
        for ty in reg.names() {
            for round in 0..60 {
                let len = (next() % 96) as usize;
                let mut v2 = vec![0, 6 + (round % 4) as u8, 0, 0];
                // Small numbers mostly, so counts and lengths often fit.
                v2.extend((0..len).map(|_| if next() % 3 == 0 { next() as u8 } else { (next() % 4) as u8 }));
                if let Ok(v1) = to_xcdr1(ty, &v2) {
                    assert!(v1.len() <= 2 * v2.len() + 8, "{ty}: {v2:02x?}");
                }
            }
        }
    }
}
