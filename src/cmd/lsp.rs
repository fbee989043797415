//! `situ lsp`: the language server, over standard input and output (the
//! `situ-lsp` crate does the protocol).

pub fn run() -> u8 {
    situ_lsp::run_stdio().clamp(0, 255) as u8
}
