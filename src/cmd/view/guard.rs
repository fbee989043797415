//! Which requests the page's servers answer (`situ view`, `situ run …
//! --serve`): only those addressed to the server itself.
//!
//! A page the engineer visits elsewhere could otherwise read the rules and
//! the live situation through DNS rebinding: its own name, made to resolve
//! to 127.0.0.1, is then of the same origin as the server, but the browser
//! still sends that name in `Host`. So, as Jupyter and Vite's dev server
//! do, a request is answered only when its `Host` is the address the server
//! listens on — its IP address and port, `localhost` for a loopback
//! address, the name given to `--serve`, any IP address for a server on
//! every interface (a browser that sends an IP address asked for that
//! address: no name was rebound) — and when its `Origin`, if it has one, is
//! a page of that address. Anything else gets a 403 with the reason.

use std::net::{IpAddr, SocketAddr};

/// The addresses a server answers to.
#[derive(Debug, Clone)]
pub struct Guard {
    port: u16,
    /// Host names and IP addresses (IPv6 in brackets), lower case.
    names: Vec<String>,
    /// Bound to every interface: any IP address is its own.
    any_ip: bool,
}

impl Guard {
    /// The guard of a server bound to `bound`, asked for as `asked` (the
    /// host of `--serve`, or `127.0.0.1`).
    pub fn new(bound: SocketAddr, asked: &str) -> Guard {
        let ip = bound.ip();
        let mut names = vec![literal(ip)];
        if ip.is_loopback() || ip.is_unspecified() {
            names.push("localhost".into());
        }
        let asked = asked.trim_start_matches('[').trim_end_matches(']').to_ascii_lowercase();
        if asked.parse::<IpAddr>().is_err() && !names.contains(&asked) {
            names.push(asked);
        }
        Guard { port: bound.port(), names, any_ip: ip.is_unspecified() }
    }

    /// Whether a request with these `Host` and `Origin` headers is answered;
    /// the error is the reason, for the 403's body.
    pub fn check(&self, host: Option<&str>, origin: Option<&str>) -> Result<(), String> {
        let Some(host) = host else {
            return Err("refused: the request has no Host header".into());
        };
        if !self.is_own(host.trim()) {
            return Err(format!(
                "refused: Host `{host}` is not this server's address ({}); a page of another site may not read it",
                self.own()
            ));
        }
        if let Some(origin) = origin.map(str::trim) {
            let own = origin.strip_prefix("http://").filter(|h| !h.contains('/')).is_some_and(|h| self.is_own(h));
            if !own {
                return Err(format!(
                    "refused: Origin `{origin}` is not a page of this server ({}); a page of another site may not read it",
                    self.own()
                ));
            }
        }
        Ok(())
    }

    /// Whether `HOST[:PORT]` names this server.
    fn is_own(&self, host: &str) -> bool {
        let Some((name, port)) = split(host) else { return false };
        if port != self.port {
            return false;
        }
        let name = name.to_ascii_lowercase();
        if self.names.contains(&name) {
            return true;
        }
        let bare = name.strip_prefix('[').and_then(|n| n.strip_suffix(']'));
        let is_ip = match bare {
            Some(v6) => v6.parse::<std::net::Ipv6Addr>().is_ok(),
            None => name.parse::<std::net::Ipv4Addr>().is_ok(),
        };
        self.any_ip && is_ip
    }

    /// The addresses answered, for the reason of a refusal.
    fn own(&self) -> String {
        let mut s: Vec<String> = self.names.iter().map(|n| format!("{n}:{}", self.port)).collect();
        if self.any_ip {
            s.push(format!("any IP address:{}", self.port));
        }
        s.join(", ")
    }
}

/// An IP address as a `Host` writes it.
fn literal(ip: IpAddr) -> String {
    match ip {
        IpAddr::V4(v4) => v4.to_string(),
        IpAddr::V6(v6) => format!("[{v6}]"),
    }
}

/// `NAME[:PORT]` or `[V6][:PORT]`; no port is port 80.
fn split(host: &str) -> Option<(&str, u16)> {
    let (name, port) = if host.starts_with('[') {
        let end = host.find(']')?;
        let (name, rest) = host.split_at(end + 1);
        match rest {
            "" => (name, None),
            _ => (name, Some(rest.strip_prefix(':')?)),
        }
    } else {
        match host.split_once(':') {
            Some((n, p)) => (n, Some(p)),
            None => (host, None),
        }
    };
    if name.is_empty() {
        return None;
    }
    let port = match port {
        None => 80,
        Some(p) if !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()) => p.parse().ok()?,
        Some(_) => return None,
    };
    Some((name, port))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn guard(bound: &str, asked: &str) -> Guard {
        Guard::new(bound.parse().unwrap(), asked)
    }

    #[test]
    fn a_loopback_server_answers_its_own_address_only() {
        let g = guard("127.0.0.1:8080", "127.0.0.1");
        for host in ["127.0.0.1:8080", "localhost:8080", "LocalHost:8080"] {
            assert_eq!(g.check(Some(host), None), Ok(()), "{host}");
        }
        for host in [
            "evil.example:8080",
            "127.0.0.1:8081",
            "127.0.0.1",
            "localhost",
            "127.0.0.2:8080",
            "[::1]:8080",
            "localhost.evil.example:8080",
            "127.0.0.1:8080.evil.example",
            "127.0.0.1:+8080",
            ":8080",
            "",
        ] {
            let e = g.check(Some(host), None).unwrap_err();
            assert!(e.contains(&format!("Host `{host}`")) && e.contains("127.0.0.1:8080, localhost:8080"), "{e}");
        }
        assert_eq!(g.check(None, None), Err("refused: the request has no Host header".into()));
    }

    #[test]
    fn a_foreign_origin_is_refused() {
        let g = guard("127.0.0.1:8080", "127.0.0.1");
        let host = Some("127.0.0.1:8080");
        for origin in ["http://127.0.0.1:8080", "http://localhost:8080"] {
            assert_eq!(g.check(host, Some(origin)), Ok(()), "{origin}");
        }
        for origin in [
            "http://evil.example",
            "http://evil.example:8080",
            "https://127.0.0.1:8080",
            "http://127.0.0.1:8081",
            "http://127.0.0.1:8080/x",
            "null",
            "",
        ] {
            let e = g.check(host, Some(origin)).unwrap_err();
            assert!(e.contains(&format!("Origin `{origin}`")), "{e}");
        }
    }

    #[test]
    fn other_bound_addresses() {
        let v6 = guard("[::1]:9000", "::1");
        assert_eq!(v6.check(Some("[::1]:9000"), Some("http://[::1]:9000")), Ok(()));
        assert_eq!(v6.check(Some("localhost:9000"), None), Ok(()));
        assert!(v6.check(Some("127.0.0.1:9000"), None).is_err());
        assert!(v6.check(Some("[::1]"), None).is_err());

        // On every interface: any IP address (nothing rebound), localhost, no other name.
        let all = guard("0.0.0.0:9000", "0.0.0.0");
        for host in ["192.168.1.7:9000", "[fe80::1]:9000", "localhost:9000", "0.0.0.0:9000"] {
            assert_eq!(all.check(Some(host), None), Ok(()), "{host}");
        }
        assert!(all.check(Some("evil.example:9000"), None).is_err());
        assert!(all.check(Some("192.168.1.7:9001"), None).is_err());

        // A name given to `--serve` is the server's own; port 80 may go unsaid.
        let named = guard("10.0.0.5:80", "robot.local");
        for host in ["robot.local", "robot.local:80", "10.0.0.5"] {
            assert_eq!(named.check(Some(host), None), Ok(()), "{host}");
        }
        assert!(named.check(Some("localhost:80"), None).is_err(), "not a loopback address");
        assert!(named.check(Some("10.0.0.6"), None).is_err());
    }
}
