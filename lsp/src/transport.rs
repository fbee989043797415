//! The base protocol: `Content-Length` framing over a byte stream.
//!
//! `lsp-server`'s own reader ends the connection on the first malformed
//! frame; this one reads frame by frame and turns what is not a message
//! (bad headers, bad JSON, JSON that is not a request, a response or a
//! notification) into an [`Incoming::Invalid`] that the server answers with
//! an error, so that the connection goes on.

use lsp_server::{ErrorCode, Message};
use serde_json::Value;
use std::io::{self, BufRead, Read, Write};

/// The longest header line read.
const MAX_HEADER_LINE: u64 = 8 * 1024;
/// The largest message body accepted (the compiler reads sources up to 16 MiB;
/// JSON escaping may double them).
pub const MAX_BODY: usize = 64 * 1024 * 1024;

/// What one frame held.
#[derive(Debug)]
pub enum Incoming {
    Message(Message),
    /// Not a message: answer with this error (for the request `id`, when it
    /// could be read, otherwise `null`).
    Invalid {
        id: Value,
        code: i32,
        message: String,
    },
}

fn invalid(id: Value, code: ErrorCode, message: impl Into<String>) -> Incoming {
    Incoming::Invalid { id, code: code as i32, message: message.into() }
}

/// Reads one frame; `None` at the end of the input.
pub fn read(r: &mut impl BufRead) -> io::Result<Option<Incoming>> {
    let mut length: Option<Result<usize, String>> = None;
    let mut other = None;
    let mut saw_header = false;
    loop {
        let mut line = Vec::new();
        let n = r.by_ref().take(MAX_HEADER_LINE).read_until(b'\n', &mut line)?;
        if n == 0 {
            return Ok(None);
        }
        if !line.ends_with(b"\n") && n as u64 == MAX_HEADER_LINE {
            // Too long for a header: skip the rest of the line.
            let mut sink = Vec::new();
            loop {
                sink.clear();
                let m = r.by_ref().take(MAX_HEADER_LINE).read_until(b'\n', &mut sink)?;
                if m == 0 || sink.ends_with(b"\n") {
                    break;
                }
            }
            other.get_or_insert_with(|| "a header line is too long".to_string());
            saw_header = true;
            continue;
        }
        let text = String::from_utf8_lossy(&line);
        let t = text.trim_end_matches(['\r', '\n']);
        if t.is_empty() {
            if saw_header {
                break;
            }
            continue; // blank lines between frames
        }
        saw_header = true;
        match t.split_once(':') {
            Some((k, v)) if k.trim().eq_ignore_ascii_case("content-length") => {
                length = Some(v.trim().parse::<usize>().map_err(|_| format!("bad Content-Length `{}`", v.trim())));
            }
            Some((k, _)) if k.trim().eq_ignore_ascii_case("content-type") => {}
            _ => {
                let shown: String = t.chars().take(60).collect();
                other.get_or_insert_with(|| format!("not a header: `{shown}`"));
            }
        }
    }
    let length = match length {
        Some(Ok(n)) => n,
        Some(Err(e)) => return Ok(Some(invalid(Value::Null, ErrorCode::ParseError, e))),
        None => {
            let why = other.unwrap_or_else(|| "no Content-Length header".into());
            return Ok(Some(invalid(Value::Null, ErrorCode::ParseError, format!("{why}; no Content-Length header"))));
        }
    };
    if length > MAX_BODY {
        let skipped = io::copy(&mut r.by_ref().take(length as u64), &mut io::sink())?;
        if (skipped as usize) < length {
            return Ok(None);
        }
        return Ok(Some(invalid(
            Value::Null,
            ErrorCode::InvalidRequest,
            format!("a message of {length} bytes is over the limit of {MAX_BODY}"),
        )));
    }
    let mut body = vec![0; length];
    if let Err(e) = r.read_exact(&mut body) {
        return if e.kind() == io::ErrorKind::UnexpectedEof { Ok(None) } else { Err(e) };
    }
    Ok(Some(decode(&body)))
}

/// One body as a message.
pub fn decode(body: &[u8]) -> Incoming {
    let value: Value = match serde_json::from_slice(body) {
        Ok(v) => v,
        Err(e) => return invalid(Value::Null, ErrorCode::ParseError, format!("not JSON: {e}")),
    };
    let id = match value.get("id") {
        Some(id @ (Value::Number(_) | Value::String(_))) => id.clone(),
        _ => Value::Null,
    };
    let has = |k: &str| value.get(k).is_some_and(|v| !v.is_null());
    let parsed = if !value.is_object() {
        Err("not an object".to_string())
    } else if value.get("method").is_some() {
        if !value["method"].is_string() {
            Err("the method is not a string".to_string())
        } else if has("id") {
            serde_json::from_value(value).map(Message::Request).map_err(|e| e.to_string())
        } else {
            serde_json::from_value(value).map(Message::Notification).map_err(|e| e.to_string())
        }
    } else if has("id") && (value.get("result").is_some() || has("error")) {
        serde_json::from_value(value).map(Message::Response).map_err(|e| e.to_string())
    } else {
        Err("neither a request, a notification nor a response".to_string())
    };
    match parsed {
        Ok(m) => Incoming::Message(m),
        Err(e) => invalid(id, ErrorCode::InvalidRequest, format!("not a JSON-RPC message: {e}")),
    }
}

/// Writes one message with its header.
pub fn write(w: &mut impl Write, value: &Value) -> io::Result<()> {
    let body = serde_json::to_string(value)?;
    write!(w, "Content-Length: {}\r\n\r\n{}", body.len(), body)?;
    w.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frames(input: &str) -> Vec<Incoming> {
        let mut r = io::BufReader::new(input.as_bytes());
        let mut out = Vec::new();
        for _ in 0..100 {
            match read(&mut r).unwrap() {
                Some(f) => out.push(f),
                None => break,
            }
        }
        out
    }

    fn frame(body: &str) -> String {
        format!("Content-Length: {}\r\n\r\n{}", body.len(), body)
    }

    #[test]
    fn garbage_does_not_end_the_stream() {
        let ok = r#"{"jsonrpc":"2.0","id":7,"method":"shutdown"}"#;
        let input = [
            frame("{not json"),
            frame(r#"{"jsonrpc":"2.0","id":3,"method":5}"#),
            "Content-Length: nope\r\n\r\n".to_string(),
            "hello\r\n\r\n".to_string(),
            frame(ok),
        ]
        .concat();
        let got = frames(&input);
        assert_eq!(got.len(), 5, "{got:?}");
        assert!(matches!(&got[0], Incoming::Invalid { code: -32700, id: Value::Null, .. }));
        assert!(matches!(&got[1], Incoming::Invalid { code: -32600, id, .. } if id == 3));
        assert!(matches!(&got[2], Incoming::Invalid { code: -32700, .. }));
        assert!(matches!(&got[3], Incoming::Invalid { code: -32700, .. }));
        assert!(matches!(&got[4], Incoming::Message(Message::Request(r)) if r.method == "shutdown"));
    }

    #[test]
    fn a_cut_body_is_the_end() {
        assert!(frames("Content-Length: 100\r\n\r\n{}").is_empty());
    }

    #[test]
    fn write_frames_a_value() {
        let mut out = Vec::new();
        write(&mut out, &serde_json::json!({"a": 1})).unwrap();
        assert_eq!(String::from_utf8(out).unwrap(), "Content-Length: 7\r\n\r\n{\"a\":1}");
    }
}
