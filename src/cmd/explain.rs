//! `situ explain CODE`.

use super::{OK, USAGE};
use situ_compiler::codes;

pub fn run(code: Option<&str>) -> u8 {
    let Some(code) = code else {
        for c in codes::ALL {
            println!("situ::{}  {:<7}  {}", c.code, c.severity.as_str(), c.title);
        }
        return OK;
    };
    match codes::lookup(code) {
        Some(c) => {
            print!("{}", c.explain);
            OK
        }
        None => {
            eprintln!("error: unknown diagnostic code `{code}`; `situ explain` lists them all");
            USAGE
        }
    }
}
