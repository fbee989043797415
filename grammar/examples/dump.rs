//! Prints the AST and the syntax errors of a file: `cargo run -p situ-grammar --example dump FILE`.
fn main() {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: dump FILE");
        std::process::exit(2);
    };
    let src = match std::fs::read_to_string(&path) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{path}: {e}");
            std::process::exit(2);
        }
    };
    let parsed = situ_grammar::parse(&src, situ_grammar::diag::FileId(0));
    println!("{:#?}", parsed.file);
    for e in &parsed.errors {
        let line = src[..e.primary.span.start].lines().count();
        eprintln!("{}:{line}: {} [{}]", path, e.message, e.code);
    }
}
