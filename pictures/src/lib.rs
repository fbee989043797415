//! DOT to SVG, for every picture situ draws (the compiler writes the DOT:
//! `situ_compiler::graph`). Graphviz's `dot` (Debian's `graphviz`) when it
//! is on the PATH: its layered layout reduces crossings, keeps every label
//! on its edge and draws every border style, which is what makes the
//! pictures of a real rule file readable (`docs/language.md` §10.13,
//! "Pictures"). Without it, the built-in layered layout ([`builtin`]) lays
//! the same DOT out, with its title, its legend and no edge over a box.
//! `SITU_LAYOUT=builtin` chooses the built-in layout; `SITU_DOT=PATH`
//! names the `dot` to run.

pub mod builtin;

use std::io::Write as _;
use std::path::PathBuf;
use std::process::{Command, Stdio};

/// Why a picture was not laid out.
#[derive(Debug, thiserror::Error)]
pub enum LayoutError {
    /// The DOT text does not parse (the built-in layout's parser says why).
    #[error("the DOT text does not parse: {0}")]
    Dot(String),
    #[error("cannot run `{}`: {source}", path.display())]
    Spawn { path: PathBuf, source: std::io::Error },
    #[error("`{}`: {source}", path.display())]
    Wait { path: PathBuf, source: std::io::Error },
    #[error("`{}` failed: {stderr}", path.display())]
    Failed { path: PathBuf, stderr: String },
    #[error("`{}` wrote non-UTF-8 SVG", path.display())]
    NotUtf8 { path: PathBuf },
    #[error("`{}` wrote {got} pictures for {asked} graphs", path.display())]
    Count { path: PathBuf, got: usize, asked: usize },
}

/// Who lays the pictures out.
pub enum Engine {
    Graphviz(PathBuf),
    /// The built-in layout, and why (no `dot`, or asked for).
    Builtin(String),
}

/// Graphviz's `dot` if it can be found, else the built-in layout.
pub fn engine() -> Engine {
    if std::env::var_os("SITU_LAYOUT").is_some_and(|v| v == "builtin") {
        return Engine::Builtin("SITU_LAYOUT=builtin".into());
    }
    if let Some(dot) = std::env::var_os("SITU_DOT") {
        return Engine::Graphviz(dot.into());
    }
    let found = std::env::var_os("PATH")
        .and_then(|paths| std::env::split_paths(&paths).map(|p| p.join("dot")).find(|p| p.is_file()));
    match found {
        Some(dot) => Engine::Graphviz(dot),
        None => Engine::Builtin("Graphviz's `dot` is not on the PATH".into()),
    }
}

/// One DOT graph to SVG with the engine found by [`engine`].
pub fn svg(dot: &str) -> Result<String, LayoutError> {
    svgs(&engine(), &[dot]).map(|mut v| v.remove(0))
}

/// Several DOT graphs to SVG, one SVG document each (one run of `dot`).
pub fn svgs(engine: &Engine, dots: &[&str]) -> Result<Vec<String>, LayoutError> {
    match engine {
        Engine::Builtin(_) => dots.iter().map(|d| builtin::svg(d)).collect(),
        Engine::Graphviz(path) => graphviz(path, dots),
    }
}

fn graphviz(path: &PathBuf, dots: &[&str]) -> Result<Vec<String>, LayoutError> {
    let mut child = Command::new(path)
        .arg("-Tsvg")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|source| LayoutError::Spawn { path: path.clone(), source })?;
    let input: String = dots.concat();
    let mut stdin = child.stdin.take().expect("piped");
    // Written from a thread: `dot` may fill its output pipe before it has read all its input.
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let output = child.wait_with_output().map_err(|source| LayoutError::Wait { path: path.clone(), source })?;
    let _ = writer.join();
    if !output.status.success() {
        let stderr = String::from_utf8_lossy(&output.stderr).trim().to_string();
        return Err(LayoutError::Failed { path: path.clone(), stderr });
    }
    let text = String::from_utf8(output.stdout).map_err(|_| LayoutError::NotUtf8 { path: path.clone() })?;
    let docs: Vec<String> = text.split("<?xml").filter(|d| !d.trim().is_empty()).map(|d| format!("<?xml{d}")).collect();
    if docs.len() != dots.len() {
        return Err(LayoutError::Count { path: path.clone(), got: docs.len(), asked: dots.len() });
    }
    Ok(docs)
}

/// An SVG document's size (in its own units, `pt` or `px`), view box and
/// content.
struct Doc<'a> {
    width: f64,
    height: f64,
    view_box: String,
    inner: &'a str,
}

fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let at = tag.find(&format!(" {name}=\""))? + name.len() + 3;
    let end = tag[at..].find('"')?;
    Some(&tag[at..at + end])
}

fn number(s: &str) -> Option<f64> {
    s.trim_end_matches(|c: char| c.is_ascii_alphabetic()).trim().parse().ok()
}

fn parse(svg: &str) -> Option<Doc<'_>> {
    let start = svg.find("<svg")?;
    let open_end = start + svg[start..].find('>')?;
    let tag = &svg[start..open_end];
    let width = number(attr(tag, "width")?)?;
    let height = number(attr(tag, "height")?)?;
    let view_box = attr(tag, "viewBox").map_or(format!("0 0 {width} {height}"), str::to_string);
    let close = svg.rfind("</svg>")?;
    Some(Doc { width, height, view_box, inner: &svg[open_end + 1..close] })
}

/// Small multiples: the pictures in a grid (the number of columns that
/// makes the whole most nearly square), under a title.
pub fn compose(title: &str, cells: &[String]) -> String {
    const GAP: f64 = 16.0;
    const TITLE: f64 = 36.0;
    let docs: Vec<Doc> = cells.iter().filter_map(|c| parse(c)).collect();
    let n = docs.len().max(1);
    let grid = |cols: usize| {
        let mut col_w = vec![0f64; cols];
        let mut row_h = vec![0f64; n.div_ceil(cols)];
        for (i, d) in docs.iter().enumerate() {
            col_w[i % cols] = col_w[i % cols].max(d.width);
            row_h[i / cols] = row_h[i / cols].max(d.height);
        }
        (col_w, row_h)
    };
    let size = |(w, h): &(Vec<f64>, Vec<f64>)| {
        (w.iter().sum::<f64>() + GAP * (w.len() + 1) as f64, h.iter().sum::<f64>() + GAP * (h.len() + 1) as f64 + TITLE)
    };
    let cols = (1..=n)
        .min_by(|&a, &b| {
            let (wa, ha) = size(&grid(a));
            let (wb, hb) = size(&grid(b));
            wa.max(ha).total_cmp(&wb.max(hb))
        })
        .unwrap_or(1);
    let (col_w, row_h) = grid(cols);
    let (w, h) = size(&(col_w.clone(), row_h.clone()));
    let mut out = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"no\"?>\n\
         <svg width=\"{w:.0}pt\" height=\"{h:.0}pt\" viewBox=\"0 0 {w:.0} {h:.0}\" xmlns=\"http://www.w3.org/2000/svg\" \
         xmlns:xlink=\"http://www.w3.org/1999/xlink\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n\
         <text x=\"{:.0}\" y=\"26\" text-anchor=\"middle\" font-family=\"Helvetica,sans-Serif\" font-size=\"20.00\">{}</text>\n",
        w / 2.0,
        xml(title)
    );
    for (i, d) in docs.iter().enumerate() {
        let (c, r) = (i % cols, i / cols);
        let x = GAP + col_w[..c].iter().sum::<f64>() + GAP * c as f64;
        let y = TITLE + GAP + row_h[..r].iter().sum::<f64>() + GAP * r as f64;
        out.push_str(&format!(
            "<svg x=\"{x:.1}\" y=\"{y:.1}\" width=\"{:.1}\" height=\"{:.1}\" viewBox=\"{}\">\n{}</svg>\n",
            d.width, d.height, d.view_box, d.inner
        ));
    }
    out.push_str("</svg>\n");
    out
}

fn xml(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}
