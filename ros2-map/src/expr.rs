//! Map expressions: field paths (`a.b`, `a[0]`), the reducers `min`, `max`,
//! `mean`, `len`, numbers, strings, `+ - * /`, comparisons, `and`, `or`,
//! `not`. A hand parser that never panics and bounds its nesting; every
//! place is a byte range of the expression's text.

/// A byte range of the expression's text.
pub type Range = (usize, usize);

/// The longest expression read, in bytes.
pub const MAX_LEN: usize = 4096;
/// The deepest nesting of parentheses, `not`, signs and reducers.
pub const MAX_DEPTH: usize = 32;
/// The most tokens of one expression: a bound on the depth of the tree that
/// a long chain of operators (`a + a + …`) builds.
pub const MAX_TOKENS: usize = 512;

/// One step of a field path.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    Field(String, Range),
    /// `[i]`, with the range of the brackets.
    Index(u64, Range),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
    Ne,
    And,
    Or,
}

impl BinOp {
    pub fn text(self) -> &'static str {
        match self {
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
            BinOp::Lt => "<",
            BinOp::Le => "<=",
            BinOp::Gt => ">",
            BinOp::Ge => ">=",
            BinOp::Eq => "==",
            BinOp::Ne => "!=",
            BinOp::And => "and",
            BinOp::Or => "or",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reducer {
    Min,
    Max,
    Mean,
    Len,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    Number(f64, Range),
    Str(String, Range),
    Bool(bool, Range),
    /// A field path: its first name, then steps.
    Path(Vec<Step>, Range),
    Neg(Box<Expr>, Range),
    Not(Box<Expr>, Range),
    Reduce(Reducer, Box<Expr>, Range),
    Binary(BinOp, Box<Expr>, Box<Expr>, Range),
}

impl Expr {
    pub fn range(&self) -> Range {
        match self {
            Expr::Number(_, r)
            | Expr::Str(_, r)
            | Expr::Bool(_, r)
            | Expr::Path(_, r)
            | Expr::Neg(_, r)
            | Expr::Not(_, r)
            | Expr::Reduce(_, _, r)
            | Expr::Binary(_, _, _, r) => *r,
        }
    }
}

/// A syntax error: what is wrong and where.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntaxError {
    pub message: String,
    pub range: Range,
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Num(f64),
    Str(String),
    Ident(String),
    Sym(&'static str),
}

fn err<T>(message: impl Into<String>, range: Range) -> Result<T, SyntaxError> {
    Err(SyntaxError { message: message.into(), range })
}

fn lex(text: &str) -> Result<Vec<(Tok, Range)>, SyntaxError> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        let start = i;
        if c.is_ascii_whitespace() {
            i += 1;
        } else if c.is_ascii_digit() {
            while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
                i += 1;
            }
            if i < bytes.len() && (bytes[i] == b'e' || bytes[i] == b'E') {
                i += 1;
                if i < bytes.len() && (bytes[i] == b'+' || bytes[i] == b'-') {
                    i += 1;
                }
                while i < bytes.len() && bytes[i].is_ascii_digit() {
                    i += 1;
                }
            }
            match text[start..i].parse::<f64>() {
                Ok(n) if n.is_finite() => out.push((Tok::Num(n), (start, i))),
                _ => return err(format!("`{}` is not a number", &text[start..i]), (start, i)),
            }
        } else if c.is_ascii_alphabetic() || c == b'_' {
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            out.push((Tok::Ident(text[start..i].to_string()), (start, i)));
        } else if c == b'"' || c == b'\'' {
            i += 1;
            while i < bytes.len() && bytes[i] != c {
                i += 1;
            }
            if i >= bytes.len() {
                return err("string without its closing quote", (start, bytes.len()));
            }
            out.push((Tok::Str(text[start + 1..i].to_string()), (start, i + 1)));
            i += 1;
        } else {
            let two = text.get(i..i + 2).unwrap_or("");
            let sym = ["<=", ">=", "==", "!="].into_iter().find(|s| *s == two).or_else(|| {
                ["<", ">", "+", "-", "*", "/", "(", ")", "[", "]", "."].into_iter().find(|s| s.as_bytes()[0] == c)
            });
            match sym {
                Some(s) => {
                    i += s.len();
                    out.push((Tok::Sym(s), (start, i)));
                }
                None => {
                    let ch = text[start..].chars().next().unwrap_or('?');
                    return err(format!("unexpected `{ch}`"), (start, start + ch.len_utf8()));
                }
            }
        }
    }
    Ok(out)
}

struct Parser {
    toks: Vec<(Tok, Range)>,
    pos: usize,
    end: usize,
    depth: usize,
}

/// Parses one expression.
pub fn parse(text: &str) -> Result<Expr, SyntaxError> {
    if text.len() > MAX_LEN {
        return err(format!("expression longer than {MAX_LEN} bytes"), (0, text.len()));
    }
    let toks = lex(text)?;
    if toks.len() > MAX_TOKENS {
        return err(format!("expression of more than {MAX_TOKENS} tokens"), (toks[MAX_TOKENS].1 .0, text.len()));
    }
    let mut p = Parser { toks, pos: 0, end: text.len(), depth: 0 };
    if p.toks.is_empty() {
        return err("empty expression", (0, text.len()));
    }
    let e = p.or()?;
    match p.toks.get(p.pos) {
        None => Ok(e),
        Some((_, r)) => err("unexpected text after the expression", (r.0, p.end)),
    }
}

impl Parser {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.pos).map(|(t, _)| t)
    }

    fn here(&self) -> Range {
        self.toks.get(self.pos).map_or((self.end, self.end), |(_, r)| *r)
    }

    fn is_sym(&self, s: &str) -> bool {
        matches!(self.peek(), Some(Tok::Sym(t)) if *t == s)
    }

    fn is_word(&self, w: &str) -> bool {
        matches!(self.peek(), Some(Tok::Ident(t)) if t == w)
    }

    fn expect(&mut self, s: &str) -> Result<Range, SyntaxError> {
        if self.is_sym(s) {
            self.pos += 1;
            Ok(self.toks[self.pos - 1].1)
        } else {
            err(format!("expected `{s}`"), self.here())
        }
    }

    fn deeper(&mut self) -> Result<(), SyntaxError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return err(format!("expression nested more than {MAX_DEPTH} deep"), self.here());
        }
        Ok(())
    }

    fn binary(&mut self, op: BinOp, l: Expr, r: Expr) -> Expr {
        let range = (l.range().0, r.range().1);
        Expr::Binary(op, Box::new(l), Box::new(r), range)
    }

    fn or(&mut self) -> Result<Expr, SyntaxError> {
        self.deeper()?;
        let mut l = self.and()?;
        while self.is_word("or") {
            self.pos += 1;
            let r = self.and()?;
            l = self.binary(BinOp::Or, l, r);
        }
        self.depth -= 1;
        Ok(l)
    }

    fn and(&mut self) -> Result<Expr, SyntaxError> {
        let mut l = self.not()?;
        while self.is_word("and") {
            self.pos += 1;
            let r = self.not()?;
            l = self.binary(BinOp::And, l, r);
        }
        Ok(l)
    }

    fn not(&mut self) -> Result<Expr, SyntaxError> {
        if self.is_word("not") {
            let start = self.here().0;
            self.pos += 1;
            self.deeper()?;
            let e = self.not()?;
            self.depth -= 1;
            let range = (start, e.range().1);
            return Ok(Expr::Not(Box::new(e), range));
        }
        self.cmp()
    }

    fn cmp(&mut self) -> Result<Expr, SyntaxError> {
        let l = self.add()?;
        let op = match self.peek() {
            Some(Tok::Sym("<")) => BinOp::Lt,
            Some(Tok::Sym("<=")) => BinOp::Le,
            Some(Tok::Sym(">")) => BinOp::Gt,
            Some(Tok::Sym(">=")) => BinOp::Ge,
            Some(Tok::Sym("==")) => BinOp::Eq,
            Some(Tok::Sym("!=")) => BinOp::Ne,
            _ => return Ok(l),
        };
        self.pos += 1;
        let r = self.add()?;
        Ok(self.binary(op, l, r))
    }

    fn add(&mut self) -> Result<Expr, SyntaxError> {
        let mut l = self.mul()?;
        loop {
            let op = match self.peek() {
                Some(Tok::Sym("+")) => BinOp::Add,
                Some(Tok::Sym("-")) => BinOp::Sub,
                _ => return Ok(l),
            };
            self.pos += 1;
            let r = self.mul()?;
            l = self.binary(op, l, r);
        }
    }

    fn mul(&mut self) -> Result<Expr, SyntaxError> {
        let mut l = self.unary()?;
        loop {
            let op = match self.peek() {
                Some(Tok::Sym("*")) => BinOp::Mul,
                Some(Tok::Sym("/")) => BinOp::Div,
                _ => return Ok(l),
            };
            self.pos += 1;
            let r = self.unary()?;
            l = self.binary(op, l, r);
        }
    }

    fn unary(&mut self) -> Result<Expr, SyntaxError> {
        if self.is_sym("-") {
            let start = self.here().0;
            self.pos += 1;
            self.deeper()?;
            let e = self.unary()?;
            self.depth -= 1;
            let range = (start, e.range().1);
            return Ok(Expr::Neg(Box::new(e), range));
        }
        self.primary()
    }

    fn primary(&mut self) -> Result<Expr, SyntaxError> {
        let here = self.here();
        let Some((tok, range)) = self.toks.get(self.pos).cloned() else {
            return err("expected a value", here);
        };
        self.pos += 1;
        match tok {
            Tok::Num(n) => Ok(Expr::Number(n, range)),
            Tok::Str(s) => Ok(Expr::Str(s, range)),
            Tok::Sym("(") => {
                let e = self.or()?;
                self.expect(")")?;
                Ok(e)
            }
            Tok::Ident(w) if w == "true" || w == "false" => Ok(Expr::Bool(w == "true", range)),
            Tok::Ident(w) if matches!(w.as_str(), "and" | "or" | "not") => {
                err(format!("expected a value, found `{w}`"), range)
            }
            Tok::Ident(w) if self.is_sym("(") => {
                let reducer = match w.as_str() {
                    "min" => Reducer::Min,
                    "max" => Reducer::Max,
                    "mean" => Reducer::Mean,
                    "len" => Reducer::Len,
                    _ => return err(format!("`{w}` is not a reducer (min, max, mean, len)"), range),
                };
                self.pos += 1;
                self.deeper()?;
                let arg = self.or()?;
                self.depth -= 1;
                let close = self.expect(")")?;
                Ok(Expr::Reduce(reducer, Box::new(arg), (range.0, close.1)))
            }
            Tok::Ident(w) => {
                let mut steps = vec![Step::Field(w, range)];
                let mut end = range.1;
                loop {
                    if self.is_sym(".") {
                        self.pos += 1;
                        match self.toks.get(self.pos).cloned() {
                            Some((Tok::Ident(f), r)) => {
                                self.pos += 1;
                                end = r.1;
                                steps.push(Step::Field(f, r));
                            }
                            _ => return err("expected a field name after `.`", self.here()),
                        }
                    } else if self.is_sym("[") {
                        let open = self.here().0;
                        self.pos += 1;
                        let index = match self.toks.get(self.pos).cloned() {
                            Some((Tok::Num(n), _)) if n.fract() == 0.0 && (0.0..1e15).contains(&n) => n as u64,
                            _ => return err("expected a non-negative whole number as index", self.here()),
                        };
                        self.pos += 1;
                        let close = self.expect("]")?;
                        end = close.1;
                        steps.push(Step::Index(index, (open, close.1)));
                    } else {
                        break;
                    }
                }
                Ok(Expr::Path(steps, (range.0, end)))
            }
            Tok::Sym(s) => err(format!("expected a value, found `{s}`"), range),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn precedence_and_places() {
        let e = parse("min(ranges) < 0.5 and not x.y[2] == 'a'").unwrap();
        let Expr::Binary(BinOp::And, l, r, range) = e else { panic!("{e:?}") };
        assert_eq!(range, (0, 39));
        assert!(matches!(*l, Expr::Binary(BinOp::Lt, _, _, (0, 17))));
        assert!(matches!(*r, Expr::Not(_, _)));
        assert!(matches!(parse("1 + 2 * 3").unwrap(), Expr::Binary(BinOp::Add, _, _, _)));
    }

    #[test]
    fn errors_have_places() {
        for (text, at) in [("", 0), ("a.", 2), ("a[x]", 2), ("1 +", 3), ("foo(x)", 0), ("a b", 2), ("'x", 0), ("é", 0)]
        {
            let e = parse(text).unwrap_err();
            assert_eq!(e.range.0, at, "{text:?}: {e:?}");
            assert!(e.range.1 <= text.len());
        }
    }

    #[test]
    fn depth_is_bounded() {
        let deep = format!("{}1{}", "(".repeat(200), ")".repeat(200));
        assert!(parse(&deep).unwrap_err().message.contains("nested"));
        assert!(parse(&"not ".repeat(500)).is_err());
        assert!(parse(&"-".repeat(500)).is_err());
        assert!(parse(&"x".repeat(MAX_LEN + 1)).is_err());
        let chain = vec!["x"; 2000].join("+");
        assert!(parse(&chain).unwrap_err().message.contains("tokens"));
        assert!(parse(&vec!["x"; 256].join("+")).is_ok());
    }
}
