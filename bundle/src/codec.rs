//! Writing and reading bundle files, JSON or binary, with the checks that
//! make a damaged file an error that says what is wrong, never a panic and
//! never a half-read network.
//!
//! - **JSON** (the default): the envelope of [crate]'s documentation, with
//!   the content pretty-printed, for people and diffs.
//! - **Binary** (`situ build --binary`): `SITUBNDL`, the format version
//!   (u32 LE), the content length (u64 LE), the SHA-256 of the content, the
//!   compiler version (u32 LE length, UTF-8), then the content in postcard.
//!
//! A signed bundle ([`crate::sign`]) has a `signature` field after `sha256`
//! in JSON (`{"key_id": HEX, "ed25519": HEX}`), and in binary a trailer
//! after the content: `SITUSIG1`, the key id (8 bytes), the signature (64
//! bytes). Unsigned bundles are as before, and still load.
//!
//! Reading checks, in order: that the file is a bundle at all, that it is
//! complete, that its format version is this one, that the content's hash
//! is the recorded one, that the content decodes, and that every index in it
//! is in range ([`validate`]). Each failure is its own [`LoadError`]. A
//! signature is only read here (a malformed one is damage); whether it is
//! trusted is [`crate::sign::verify`]'s question.

use crate::signature::{KeyId, Signature, SignatureJson, KEY_ID_BYTES};
use crate::{Content, FORMAT_NAME, FORMAT_VERSION};
use serde::{Deserialize, Serialize};
use serde_json::value::RawValue;
use sha2::{Digest, Sha256};

/// How a bundle is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    Json,
    Binary,
}

const MAGIC: &[u8; 8] = b"SITUBNDL";

/// The start of a binary bundle's signature trailer.
const SIGNATURE_MAGIC: &[u8; 8] = b"SITUSIG1";
const SIGNATURE_TRAILER: usize = 8 + KEY_ID_BYTES + 64;

/// The version of the compiler that writes bundles.
pub const COMPILER_VERSION: &str = env!("CARGO_PKG_VERSION");

/// Why a file is not a bundle this runtime can load.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LoadError {
    /// Not a situ bundle at all (another kind of file).
    #[error("not a situ bundle: {reason}")]
    NotABundle { reason: String },
    /// A bundle cut short: the file ends before the content does.
    #[error("the bundle is truncated: {reason}")]
    Truncated { reason: String },
    /// A bundle whose JSON was damaged (invalid JSON inside).
    #[error("the bundle is damaged: {reason}")]
    Damaged { reason: String },
    /// Written by a newer situ, in a format this one does not know.
    #[error(
        "the bundle has format version {found} (written by situ {compiler}); this situ reads version {supported}: upgrade situ or rebuild the bundle"
    )]
    NewerFormat { found: u32, supported: u32, compiler: String },
    /// Written by an older situ, in a format this one no longer reads.
    #[error(
        "the bundle has format version {found} (written by situ {compiler}); this situ reads version {supported}: rebuild it with `situ build`"
    )]
    OlderFormat { found: u32, supported: u32, compiler: String },
    /// The content is not the one that was hashed: it was edited.
    #[error(
        "the bundle was modified after it was built: its content hashes to {found}, not to the recorded {expected}; rebuild it with `situ build`"
    )]
    Modified { expected: String, found: String },
    /// The hash matches but the content is not a valid bundle of this format.
    #[error("the bundle is invalid: {reason}")]
    Invalid { reason: String },
}

/// Why a content is not a valid bundle of this format ([`validate`]): an
/// index out of range or a value that does not fit its field, said in words.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct Invalid(pub String);

#[derive(Serialize)]
struct EnvelopeOut<'a> {
    format: &'static str,
    format_version: u32,
    compiler_version: &'static str,
    sha256: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    signature: Option<SignatureJson>,
    content: &'a RawValue,
}

#[derive(Deserialize)]
struct EnvelopeIn<'a> {
    format: Option<String>,
    format_version: Option<u32>,
    compiler_version: Option<String>,
    sha256: Option<String>,
    #[serde(default)]
    signature: Option<SignatureJson>,
    #[serde(borrow)]
    content: Option<&'a RawValue>,
}

/// The SHA-256 of bytes, in lowercase hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes).iter().map(|b| format!("{b:02x}")).collect()
}

/// The hash that names a program: the `sha256` of its JSON bundle (the same
/// content encoded in binary has another hash of its own bytes).
pub fn content_sha256(content: &Content) -> String {
    sha256_hex(serde_json::to_string_pretty(content).expect("bundle content serializes").as_bytes())
}

/// The file bytes of a bundle.
pub fn encode(content: &Content, encoding: Encoding) -> Vec<u8> {
    encode_with(content, encoding, None)
}

/// The file bytes of a bundle, signed by `sign` (given the content hash)
/// when there is one ([`crate::sign::encode_signed`]).
pub(crate) fn encode_with(content: &Content, encoding: Encoding, sign: Option<&dyn Fn(&str) -> Signature>) -> Vec<u8> {
    match encoding {
        Encoding::Json => {
            let body = serde_json::to_string_pretty(content).expect("bundle content serializes");
            let raw = RawValue::from_string(body).expect("serde_json writes valid JSON");
            let sha256 = sha256_hex(raw.get().as_bytes());
            let envelope = EnvelopeOut {
                format: FORMAT_NAME,
                format_version: FORMAT_VERSION,
                compiler_version: COMPILER_VERSION,
                signature: sign.map(|s| s(&sha256).to_json()),
                sha256,
                content: &raw,
            };
            let mut out = serde_json::to_vec(&envelope).expect("the envelope serializes");
            out.push(b'\n');
            out
        }
        Encoding::Binary => {
            let body = postcard::to_allocvec(content).expect("bundle content serializes");
            let mut out = Vec::with_capacity(body.len() + 64);
            out.extend_from_slice(MAGIC);
            out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
            out.extend_from_slice(&(body.len() as u64).to_le_bytes());
            out.extend_from_slice(&Sha256::digest(&body));
            out.extend_from_slice(&(COMPILER_VERSION.len() as u32).to_le_bytes());
            out.extend_from_slice(COMPILER_VERSION.as_bytes());
            out.extend_from_slice(&body);
            if let Some(sign) = sign {
                let signature = sign(&sha256_hex(&body));
                out.extend_from_slice(SIGNATURE_MAGIC);
                out.extend_from_slice(&signature.key_id.0);
                out.extend_from_slice(&signature.ed25519);
            }
            out
        }
    }
}

/// Reads a bundle file, JSON or binary (told apart by the first bytes).
pub fn decode(bytes: &[u8]) -> Result<Content, LoadError> {
    decode_envelope(bytes).map(|d| d.content)
}

/// A bundle read with [`decode_envelope`]: its content, and what the
/// envelope says of it.
#[derive(Debug, Clone, PartialEq)]
pub struct Decoded {
    pub content: Content,
    /// The content hash the envelope records (and the content has).
    pub sha256: String,
    pub signature: Option<Signature>,
}

/// [`decode`], keeping the envelope's hash and signature (for
/// [`crate::sign::verify`]).
pub fn decode_envelope(bytes: &[u8]) -> Result<Decoded, LoadError> {
    let decoded = if bytes.starts_with(MAGIC) {
        decode_binary(&bytes[MAGIC.len()..])?
    } else if MAGIC.starts_with(bytes) && !bytes.is_empty() {
        return Err(LoadError::Truncated { reason: format!("the file ends after {} bytes", bytes.len()) });
    } else {
        decode_json(bytes)?
    };
    validate(&decoded.content).map_err(|Invalid(reason)| LoadError::Invalid { reason })?;
    Ok(decoded)
}

fn decode_json(bytes: &[u8]) -> Result<Decoded, LoadError> {
    let text = std::str::from_utf8(bytes)
        .map_err(|e| LoadError::NotABundle { reason: format!("it is neither a JSON nor a binary bundle ({e})") })?;
    // The writer always starts with this: a file that is a piece of it is
    // a bundle cut short.
    let head = format!("{{\"format\":\"{FORMAT_NAME}\"");
    let looks_like_bundle = (!text.is_empty() && head.starts_with(text))
        || text.get(..200.min(text.len())).is_some_and(|h| h.contains(FORMAT_NAME));
    let envelope: EnvelopeIn = match serde_json::from_str(text) {
        Ok(e) => e,
        Err(e) if looks_like_bundle && e.is_eof() => {
            return Err(LoadError::Truncated { reason: format!("the JSON ends early ({e})") })
        }
        Err(e) if looks_like_bundle => return Err(LoadError::Damaged { reason: format!("invalid JSON: {e}") }),
        Err(e) if text.trim().is_empty() => {
            return Err(LoadError::NotABundle { reason: format!("the file is empty ({e})") })
        }
        Err(e) => return Err(LoadError::NotABundle { reason: format!("it is not a JSON bundle ({e})") }),
    };
    if envelope.format.as_deref() != Some(FORMAT_NAME) {
        return Err(LoadError::NotABundle {
            reason: match envelope.format {
                Some(other) => format!("its `format` is `{other}`, not `{FORMAT_NAME}`"),
                None => format!("it has no `format` field (a bundle says `\"format\": \"{FORMAT_NAME}\"`)"),
            },
        });
    }
    let compiler = envelope.compiler_version.unwrap_or_else(|| "unknown".into());
    check_version(envelope.format_version, compiler)?;
    let (Some(expected), Some(raw)) = (envelope.sha256, envelope.content) else {
        return Err(LoadError::Damaged { reason: "the `sha256` or `content` field is missing".into() });
    };
    let found = sha256_hex(raw.get().as_bytes());
    if found != expected {
        return Err(LoadError::Modified { expected, found });
    }
    let signature = match &envelope.signature {
        Some(s) => Some(Signature::from_json(s).map_err(|reason| LoadError::Damaged { reason })?),
        None => None,
    };
    let content = serde_json::from_str(raw.get()).map_err(|e| LoadError::Invalid { reason: e.to_string() })?;
    Ok(Decoded { content, sha256: found, signature })
}

fn check_version(found: Option<u32>, compiler: String) -> Result<(), LoadError> {
    match found {
        None => Err(LoadError::Damaged { reason: "the `format_version` field is missing".into() }),
        Some(found) if found > FORMAT_VERSION => {
            Err(LoadError::NewerFormat { found, supported: FORMAT_VERSION, compiler })
        }
        Some(found) if found < FORMAT_VERSION => {
            Err(LoadError::OlderFormat { found, supported: FORMAT_VERSION, compiler })
        }
        Some(_) => Ok(()),
    }
}

fn decode_binary(bytes: &[u8]) -> Result<Decoded, LoadError> {
    let mut at = 0usize;
    let mut take = |n: usize, what: &str| -> Result<&[u8], LoadError> {
        let end = at
            .checked_add(n)
            .filter(|&e| e <= bytes.len())
            .ok_or_else(|| LoadError::Truncated { reason: format!("the file ends inside the header ({what})") })?;
        let slice = &bytes[at..end];
        at = end;
        Ok(slice)
    };
    let version = u32::from_le_bytes(take(4, "format version")?.try_into().expect("4 bytes"));
    let length = u64::from_le_bytes(take(8, "content length")?.try_into().expect("8 bytes"));
    let expected: String = take(32, "hash")?.iter().map(|b| format!("{b:02x}")).collect();
    let name_len = u32::from_le_bytes(take(4, "compiler version")?.try_into().expect("4 bytes")) as usize;
    if name_len > 256 {
        return Err(LoadError::Damaged { reason: format!("a compiler version of {name_len} bytes") });
    }
    let compiler = String::from_utf8_lossy(take(name_len, "compiler version")?).into_owned();
    check_version(Some(version), compiler)?;
    let rest = &bytes[at..];
    if (rest.len() as u64) < length {
        return Err(LoadError::Truncated { reason: format!("{} of {length} content bytes", rest.len()) });
    }
    // `length` fits: it is at most `rest.len()`.
    let (body, trailer) = rest.split_at(length as usize);
    let signature = match trailer.len() {
        0 => None,
        SIGNATURE_TRAILER if trailer.starts_with(SIGNATURE_MAGIC) => {
            let (id, sig) = trailer[SIGNATURE_MAGIC.len()..].split_at(KEY_ID_BYTES);
            Some(Signature {
                key_id: KeyId(id.try_into().expect("KEY_ID_BYTES bytes")),
                ed25519: sig.try_into().expect("64 bytes"),
            })
        }
        n => return Err(LoadError::Damaged { reason: format!("{n} bytes follow the content") }),
    };
    let found = sha256_hex(body);
    if found != expected {
        return Err(LoadError::Modified { expected, found });
    }
    let content = postcard::from_bytes(body).map_err(|e| LoadError::Invalid { reason: e.to_string() })?;
    Ok(Decoded { content, sha256: found, signature })
}

/// Checks that every index of the content points at something, and that
/// values fit their fields: what a runtime relies on to never panic.
pub fn validate(c: &Content) -> Result<(), Invalid> {
    check_indexes(c).map_err(Invalid)
}

fn check_indexes(c: &Content) -> Result<(), String> {
    let (ns, na, ne) = (c.states.len(), c.agents.len(), c.events.len());
    let idx = |what: &str, i: u32, n: usize| {
        if (i as usize) < n {
            Ok(())
        } else {
            Err(format!("{what} {i} does not exist ({n} declared)"))
        }
    };
    if ns == 0 {
        return Err("it declares no state".into());
    }
    idx("initial state", c.initial, ns)?;
    for (i, e) in c.events.iter().enumerate() {
        idx(&format!("the agent of event `{}`: agent", e.name), e.agent, na)?;
        if !c.agents[e.agent as usize].events.contains(&(i as u32)) {
            return Err(format!("event `{}` is not listed by its agent", e.name));
        }
        if e.fields.len() > 64 {
            return Err(format!("event `{}` has {} fields (at most 64)", e.name, e.fields.len()));
        }
    }
    for a in &c.agents {
        if let Some(hz) = a.rate_hz {
            if !crate::rate_in_range(hz) {
                return Err(format!(
                    "agent `{}` has rate {hz} Hz (a rate must be between {} and {} Hz)",
                    a.name,
                    crate::MIN_RATE_HZ,
                    crate::MAX_RATE_HZ
                ));
            }
        }
        for &e in &a.events {
            idx(&format!("an event of agent `{}`: event", a.name), e, ne)?;
        }
        let nf = a.functions.len();
        let action = |act: &crate::Action| -> Result<(), String> {
            if let Some(f) = act.function {
                idx(&format!("a function of agent `{}`: function", a.name), f, nf)?;
            }
            for &x in act.from.iter().chain(&act.to) {
                idx(&format!("a link of agent `{}`: agent", a.name), x, na)?;
            }
            Ok(())
        };
        match &a.behaviour {
            crate::Behaviour::Always => {}
            crate::Behaviour::Table { actions } => {
                if actions.len() != ns {
                    return Err(format!("the table of `{}` has {} states, not {ns}", a.name, actions.len()));
                }
                actions.iter().flatten().try_for_each(action)?;
            }
            crate::Behaviour::Fsm(f) => {
                idx(&format!("the initial FSM state of `{}`: state", a.name), f.initial, f.states.len())?;
                f.states.iter().try_for_each(|s| action(&s.action))?;
                for t in &f.transitions {
                    idx("an FSM transition's state", t.from, f.states.len())?;
                    idx("an FSM transition's state", t.to, f.states.len())?;
                    match &t.trigger {
                        crate::Trigger::States(s) => s.iter().try_for_each(|&s| idx("a trigger state", s, ns))?,
                        crate::Trigger::Event(e) => idx("a trigger event", *e, ne)?,
                    }
                }
            }
        }
    }
    for r in &c.rules {
        idx(&format!("the target of rule `{}`: state", r.name), r.target, ns)?;
        for &a in r.matches.iter().chain(&r.stale) {
            idx(&format!("an agent of rule `{}`: agent", r.name), a, na)?;
        }
    }
    let net = &c.network;
    for node in &net.alpha {
        match node {
            crate::AlphaNode::State { states } => {
                states.iter().try_for_each(|&s| idx("an alpha node's state", s, ns))?
            }
            crate::AlphaNode::Stale { agent } => idx("an alpha node's agent", *agent, na)?,
            crate::AlphaNode::Event { event, tests, .. } => {
                idx("an alpha node's event", *event, ne)?;
                for t in tests {
                    validate_test(c, *event, t, false)?;
                }
            }
        }
    }
    for (i, b) in net.beta.iter().enumerate() {
        if let Some(p) = b.parent {
            if p as usize >= i {
                return Err(format!("beta node {i} comes before its parent {p}"));
            }
        }
        idx("a beta node's alpha node", b.alpha, net.alpha.len())?;
        let event = match &net.alpha[b.alpha as usize] {
            crate::AlphaNode::Event { event, .. } => Some(*event),
            _ => None,
        };
        for t in &b.tests {
            let Some(event) = event else { return Err(format!("beta node {i} tests fields of a fact without fields")) };
            validate_test(c, event, t, true)?;
        }
    }
    if net.terminals.len() != c.rules.len() {
        return Err(format!("{} terminal nodes for {} rules", net.terminals.len(), c.rules.len()));
    }
    for (i, t) in net.terminals.iter().enumerate() {
        if t.rule as usize != i {
            return Err(format!("terminal {i} is for rule {}", t.rule));
        }
        idx("a terminal's beta node", t.beta, net.beta.len())?;
    }
    if c.wiring.len() != ns {
        return Err(format!("{} wiring graphs for {ns} states", c.wiring.len()));
    }
    for w in &c.wiring {
        idx("a wiring graph's state", w.state, ns)?;
        for &(a, b) in &w.links {
            idx("a link's agent", a, na)?;
            idx("a link's agent", b, na)?;
        }
        for l in &w.fsm_links {
            idx("a link's agent", l.from, na)?;
            idx("a link's agent", l.to, na)?;
            idx("a link's agent", l.agent, na)?;
        }
    }
    Ok(())
}

/// A test on a field of `event`: the field exists, a constant fits its type,
/// and an operand from another fact exists (only in beta tests).
fn validate_test(c: &Content, event: u32, t: &crate::Test, beta: bool) -> Result<(), String> {
    use crate::{Check, FieldType, Operand, Value};
    let e = &c.events[event as usize];
    let Some(field) = e.fields.get(t.field as usize) else {
        return Err(format!("event `{}` has no field {}", e.name, t.field));
    };
    let operand = |o: &Operand| -> Result<(), String> {
        match o {
            Operand::Value(v) => {
                let fits = match (&field.ty, v) {
                    (FieldType::F64, Value::F64(_) | Value::I64(_)) | (FieldType::I64, Value::I64(_)) => true,
                    (FieldType::Bool, Value::Bool(_)) => true,
                    (FieldType::Symbols(s), Value::Symbol(i)) => (*i as usize) < s.len(),
                    _ => false,
                };
                if fits {
                    Ok(())
                } else {
                    Err(format!("a constant compared with `{}.{}` does not fit its type", e.name, field.name))
                }
            }
            Operand::Own { field: f } => {
                if (*f as usize) < e.fields.len() {
                    Ok(())
                } else {
                    Err(format!("event `{}` has no field {f}", e.name))
                }
            }
            Operand::Fact { agent, field: f } if beta => {
                let Some(a) = c.agents.get(*agent as usize) else {
                    return Err(format!("agent {agent} does not exist"));
                };
                // The operand reads whatever event the agent's fact is; every
                // event of the agent must have the field (the runtime checks
                // the event before reading, so this is only a sanity bound).
                if a.events.iter().any(|&ev| (*f as usize) < c.events[ev as usize].fields.len()) {
                    Ok(())
                } else {
                    Err(format!("no event of agent `{}` has field {f}", a.name))
                }
            }
            Operand::Fact { .. } => Err("an alpha test reads another fact".into()),
        }
    };
    match &t.check {
        Check::Compare { rhs, .. } => operand(rhs),
        Check::Range { lo, hi, .. } => operand(lo).and_then(|_| operand(hi)),
    }
}
