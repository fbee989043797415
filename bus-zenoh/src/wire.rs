//! The wire protocol: key expressions and JSON messages, version 1. It is
//! all another language needs to join a stack (`docs/protocol.md`, JSON
//! schemas in `bus-zenoh/schemas/`).
//!
//! | key | message | who writes | who reads |
//! |---|---|---|---|
//! | `situ/<robot>/event/<agent>` | [`EventWire`] | the agent | the Bulletinboard |
//! | `situ/<robot>/status` | [`StatusWire`] | the Bulletinboard only | every agent |
//! | `situ/<robot>/data/<from>/<to>` | [`DataWire`] | `from` | `to` |
//!
//! Names, not ids: a message names its agent, event, fields, symbols and
//! states as the rules file does. Numbers are JSON numbers (NaN and the
//! infinities as the strings `"NaN"`, `"inf"`, `"-inf"`).

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value as Json};
use situ_compiler::bundle::{Content, FieldType, Value};

/// The protocol version this build speaks.
pub const VERSION: u32 = 1;

/// The largest message accepted, in bytes.
pub const MAX_MESSAGE: usize = 1 << 20;

pub fn event_key(robot: &str, agent: &str) -> String {
    format!("situ/{robot}/event/{agent}")
}
pub fn status_key(robot: &str) -> String {
    format!("situ/{robot}/status")
}
pub fn data_key(robot: &str, from: &str, to: &str) -> String {
    format!("situ/{robot}/data/{from}/{to}")
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EventWire {
    pub v: u32,
    pub agent: String,
    pub event: String,
    pub time_ns: u64,
    #[serde(default)]
    pub payload: Map<String, Json>,
    #[serde(default)]
    pub urgent: bool,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StatusWire {
    pub v: u32,
    pub state: String,
    pub time_ns: u64,
    pub seq: u64,
    /// The epoch of the board that sends it (absent: 0). An agent follows
    /// only the highest epoch it has seen: a lower one is an old leader's.
    #[serde(default)]
    pub epoch: u64,
    /// The process of the board that sends it (absent: not said).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub board: Option<String>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DataWire {
    pub v: u32,
    pub from: String,
    pub to: String,
    pub time_ns: u64,
    #[serde(default)]
    pub urgent: bool,
    pub body: Json,
}

/// Why a message from the wire was refused.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum WireError {
    TooBig(usize),
    NotJson(String),
    Newer(u32),
    /// Well-formed, but naming something the bundle does not know, or a
    /// value of another type.
    Meaning(String),
}

impl std::fmt::Display for WireError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            WireError::TooBig(n) => write!(f, "a message of {n} bytes (at most {MAX_MESSAGE})"),
            WireError::NotJson(e) => write!(f, "not a message of this protocol: {e}"),
            WireError::Newer(v) => write!(f, "protocol version {v}; this build speaks version {VERSION}"),
            WireError::Meaning(m) => write!(f, "{m}"),
        }
    }
}

/// Parses a message of the protocol, checking size and version.
pub fn parse<T: for<'de> Deserialize<'de>>(bytes: &[u8]) -> Result<T, WireError> {
    if bytes.len() > MAX_MESSAGE {
        return Err(WireError::TooBig(bytes.len()));
    }
    let json: Json = serde_json::from_slice(bytes).map_err(|e| WireError::NotJson(e.to_string()))?;
    let v = json.get("v").and_then(Json::as_u64).ok_or_else(|| WireError::NotJson("no version `v`".into()))?;
    if v > VERSION as u64 {
        return Err(WireError::Newer(v as u32));
    }
    serde_json::from_value(json).map_err(|e| WireError::NotJson(e.to_string()))
}

/// A value as JSON.
pub fn value_json(ty: &FieldType, v: &Value) -> Json {
    match (ty, v) {
        (FieldType::Symbols(s), Value::Symbol(i)) => Json::String(s.get(*i as usize).cloned().unwrap_or_default()),
        (_, Value::F64(f)) if f.is_finite() => serde_json::json!(f),
        (_, Value::F64(f)) if f.is_nan() => Json::String("NaN".into()),
        (_, Value::F64(f)) => Json::String(if *f > 0.0 { "inf" } else { "-inf" }.into()),
        (_, Value::I64(i)) => serde_json::json!(i),
        (_, Value::Bool(b)) => Json::Bool(*b),
        (_, Value::Symbol(i)) => serde_json::json!(i),
    }
}

/// A JSON value as a value of `ty`.
pub fn json_value(ty: &FieldType, j: &Json) -> Option<Value> {
    match ty {
        FieldType::F64 => match j {
            Json::Number(n) => n.as_f64().map(Value::F64),
            Json::String(s) => match s.as_str() {
                "NaN" => Some(Value::F64(f64::NAN)),
                "inf" => Some(Value::F64(f64::INFINITY)),
                "-inf" => Some(Value::F64(f64::NEG_INFINITY)),
                _ => None,
            },
            _ => None,
        },
        FieldType::I64 => j.as_i64().map(Value::I64),
        FieldType::Bool => j.as_bool().map(Value::Bool),
        FieldType::Symbols(s) => {
            j.as_str().and_then(|x| s.iter().position(|y| y == x)).map(|i| Value::Symbol(i as u32))
        }
    }
}

/// The wire form of an event of the bundle.
pub fn event_wire(c: &Content, agent: u32, event: u32, time: u64, payload: &[Value], urgent: bool) -> EventWire {
    let e = &c.events[event as usize];
    let payload = e.fields.iter().zip(payload).map(|(f, v)| (f.name.clone(), value_json(&f.ty, v))).collect();
    EventWire {
        v: VERSION,
        agent: c.agents[agent as usize].name.clone(),
        event: e.name.clone(),
        time_ns: time,
        payload,
        urgent,
    }
}

/// An event from the wire as ids and values of the bundle; `key_agent`
/// is the agent of the key it came on.
pub fn event_of(c: &Content, key_agent: &str, w: &EventWire) -> Result<(u32, u32, Vec<Value>), WireError> {
    if w.agent != key_agent {
        return Err(WireError::Meaning(format!("an event of `{}` on the key of `{key_agent}`", w.agent)));
    }
    let agent = c.agent_id(&w.agent).ok_or_else(|| WireError::Meaning(format!("unknown agent `{}`", w.agent)))?;
    let event = c.event_id(&w.event).ok_or_else(|| WireError::Meaning(format!("unknown event `{}`", w.event)))?;
    let def = &c.events[event as usize];
    if def.agent != agent {
        return Err(WireError::Meaning(format!("`{}` is not an event of `{}`", w.event, w.agent)));
    }
    let mut payload = Vec::with_capacity(def.fields.len());
    for f in &def.fields {
        let j =
            w.payload.get(&f.name).ok_or_else(|| WireError::Meaning(format!("`{}.{}` is missing", w.event, f.name)))?;
        let v = json_value(&f.ty, j)
            .ok_or_else(|| WireError::Meaning(format!("`{}.{}` is not a {}", w.event, f.name, f.ty.describe())))?;
        payload.push(v);
    }
    if w.payload.len() != def.fields.len() {
        return Err(WireError::Meaning(format!("`{}` has fields the rules do not declare", w.event)));
    }
    Ok((agent, event, payload))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn content() -> Content {
        let c = situ_compiler::check_source(
            "t.situ",
            "states { A initial B } agent LADAR sensor { event LAOBS { distance: f64, side: {left, right} } }
             rule r { when state == A and LAOBS then B }",
        );
        situ_compiler::bundle::build(&c)
    }

    #[test]
    fn events_round_trip_through_json() {
        let c = content();
        let w = event_wire(&c, 0, 0, 42, &[Value::F64(f64::NAN), Value::Symbol(1)], true);
        let text = serde_json::to_vec(&w).unwrap();
        let back: EventWire = parse(&text).unwrap();
        let (agent, event, payload) = event_of(&c, "LADAR", &back).unwrap();
        assert_eq!((agent, event, back.urgent), (0, 0, true));
        assert!(matches!(payload[0], Value::F64(x) if x.is_nan()));
        assert_eq!(payload[1], Value::Symbol(1));
    }

    #[test]
    fn a_status_without_an_epoch_is_epoch_0_and_the_fields_round_trip() {
        let old: StatusWire = serde_json::from_str(r#"{"v":1,"state":"RS","time_ns":5,"seq":2}"#).unwrap();
        assert_eq!((old.epoch, old.board.as_deref()), (0, None));
        assert_eq!(serde_json::to_string(&old).unwrap(), r#"{"v":1,"state":"RS","time_ns":5,"seq":2,"epoch":0}"#);
        let new = StatusWire { epoch: 7, board: Some("b".into()), ..old };
        let text = serde_json::to_string(&new).unwrap();
        assert_eq!(serde_json::from_str::<StatusWire>(&text).unwrap(), new);
    }

    #[test]
    fn garbage_is_refused_with_the_reason() {
        let c = content();
        assert!(matches!(parse::<EventWire>(b"\x00\x01"), Err(WireError::NotJson(_))));
        assert!(matches!(parse::<EventWire>(br#"{"v": 9, "x": 1}"#), Err(WireError::Newer(9))));
        assert!(matches!(parse::<EventWire>(&vec![b' '; MAX_MESSAGE + 1]), Err(WireError::TooBig(_))));
        let w = |agent: &str, event: &str, payload: &str| -> EventWire {
            parse(
                format!(r#"{{"v":1,"agent":"{agent}","event":"{event}","time_ns":1,"payload":{payload}}}"#).as_bytes(),
            )
            .unwrap()
        };
        let cases = [
            (w("LADAR", "NOPE", "{}"), "LADAR", "unknown event"),
            (w("GHOST", "LAOBS", "{}"), "GHOST", "unknown agent"),
            (w("LADAR", "LAOBS", "{}"), "STCCD", "on the key of"),
            (w("LADAR", "LAOBS", r#"{"distance": 1.0}"#), "LADAR", "is missing"),
            (w("LADAR", "LAOBS", r#"{"distance": "far", "side": "left"}"#), "LADAR", "is not a f64"),
            (w("LADAR", "LAOBS", r#"{"distance": 1.0, "side": "up"}"#), "LADAR", "is not a {left, right}"),
        ];
        for (msg, key, want) in cases {
            let e = event_of(&c, key, &msg).unwrap_err().to_string();
            assert!(e.contains(want), "{e}");
        }
    }
}
