//! Map expressions: field paths (`a.b`, `a[0]`, `a[-1]`, `a[i + 1]`), the
//! functions (`min`, `max`, `mean`, `len`, `any`, `all`, `count`, `find`,
//! `index`, `abs`, `sqrt`, `hypot`, `norm`, `yaw`, `pitch`, `roll`),
//! numbers, strings, `+ - * /`, comparisons, `and`, `or`, `not`. A hand
//! parser that never panics and bounds its nesting; every place is a byte
//! range of the expression's text.

use situ_compiler::suggest::suggest;

/// A byte range of the expression's text.
pub type Range = (usize, usize);

/// The longest expression read, in bytes.
pub const MAX_LEN: usize = 4096;
/// The deepest nesting of parentheses, `not`, signs, functions and indexes.
pub const MAX_DEPTH: usize = 32;
/// The most tokens of one expression: a bound on the depth of the tree that
/// a long chain of operators (`a + a + …`) builds.
pub const MAX_TOKENS: usize = 512;

/// One step of a field path.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    Field(String, Range),
    /// `[i]`, a whole number written as such, with the range of the brackets.
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

/// The one-argument reducers of an array of numbers (and `len`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reducer {
    Min,
    Max,
    Mean,
    Len,
}

impl Reducer {
    pub fn name(self) -> &'static str {
        match self {
            Reducer::Min => "min",
            Reducer::Max => "max",
            Reducer::Mean => "mean",
            Reducer::Len => "len",
        }
    }
}

/// The functions of more than a reducer: over the elements of an array (the
/// second argument read in the element's scope), or of numbers and vectors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Func {
    /// `any(array, condition)`
    Any,
    /// `all(array, condition)`
    All,
    /// `count(array, condition)`
    Count,
    /// `min(array, number)`
    Min,
    /// `max(array, number)`
    Max,
    /// `mean(array, number)`
    Mean,
    /// `find(array, condition)`: the first element where it holds.
    Find,
    /// `index(array, value)`: the index of the first element equal to it.
    Index,
    Abs,
    Sqrt,
    /// `hypot(a, b)`
    Hypot,
    /// `norm(v)` of a message with `x y z` or of an array of numbers.
    Norm,
    /// Angles of a quaternion (`x y z w`), in radians.
    Yaw,
    Pitch,
    Roll,
}

/// Every function name, as written; `min`, `max`, `mean` and `len` with one
/// argument are the [`Reducer`]s.
pub const FUNCTIONS: &[&str] = &[
    "min", "max", "mean", "len", "any", "all", "count", "find", "index", "abs", "sqrt", "hypot", "norm", "yaw",
    "pitch", "roll",
];

impl Func {
    pub fn name(self) -> &'static str {
        match self {
            Func::Any => "any",
            Func::All => "all",
            Func::Count => "count",
            Func::Min => "min",
            Func::Max => "max",
            Func::Mean => "mean",
            Func::Find => "find",
            Func::Index => "index",
            Func::Abs => "abs",
            Func::Sqrt => "sqrt",
            Func::Hypot => "hypot",
            Func::Norm => "norm",
            Func::Yaw => "yaw",
            Func::Pitch => "pitch",
            Func::Roll => "roll",
        }
    }

    /// Whether the second argument is read in the scope of each element of
    /// the first.
    pub fn over_elements(self) -> bool {
        matches!(self, Func::Any | Func::All | Func::Count | Func::Min | Func::Max | Func::Mean | Func::Find)
    }

    /// How the function is called, with an example.
    pub fn usage(self) -> &'static str {
        match self {
            Func::Any => "`any(array, condition)`, e.g. `any(status, level >= 2)`",
            Func::All => "`all(array, condition)`, e.g. `all(status, level == 0)`",
            Func::Count => "`count(array, condition)`, e.g. `count(ranges, it < 0.5)`",
            Func::Min => "`min(array)` or `min(array, number)`, e.g. `min(status, level)`",
            Func::Max => "`max(array)` or `max(array, number)`, e.g. `max(status, level)`",
            Func::Mean => "`mean(array)` or `mean(array, number)`, e.g. `mean(status, level)`",
            Func::Find => "`find(array, condition)`, e.g. `find(status, name == 'motor').level`",
            Func::Index => "`index(array, value)`, e.g. `position[index(name, 'elbow')]`",
            Func::Abs => "`abs(number)`",
            Func::Sqrt => "`sqrt(number)`",
            Func::Hypot => "`hypot(number, number)`",
            Func::Norm => "`norm(vector)` of a message with `x y z` or of an array of numbers",
            Func::Yaw | Func::Pitch | Func::Roll => "`yaw(q)`, `pitch(q)`, `roll(q)` of a quaternion (`x y z w`)",
        }
    }

    fn arity(self) -> usize {
        match self {
            Func::Any | Func::All | Func::Count | Func::Min | Func::Max | Func::Mean => 2,
            Func::Find | Func::Index | Func::Hypot => 2,
            Func::Abs | Func::Sqrt | Func::Norm | Func::Yaw | Func::Pitch | Func::Roll => 1,
        }
    }

    fn of(name: &str) -> Option<Func> {
        Some(match name {
            "any" => Func::Any,
            "all" => Func::All,
            "count" => Func::Count,
            "min" => Func::Min,
            "max" => Func::Max,
            "mean" => Func::Mean,
            "find" => Func::Find,
            "index" => Func::Index,
            "abs" => Func::Abs,
            "sqrt" => Func::Sqrt,
            "hypot" => Func::Hypot,
            "norm" => Func::Norm,
            "yaw" => Func::Yaw,
            "pitch" => Func::Pitch,
            "roll" => Func::Roll,
            _ => return None,
        })
    }
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
    /// A function and its arguments.
    Call(Func, Vec<Expr>, Range),
    /// `.name` of a value that is not a plain path (`find(…).level`): the
    /// value, the name, the name's range, the whole range.
    Member(Box<Expr>, String, Range, Range),
    /// `[i]` with an index that is not a whole number written as such
    /// (`a[-1]`, `a[index(…)]`): the array, the index, the whole range.
    At(Box<Expr>, Box<Expr>, Range),
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
            | Expr::Binary(_, _, _, r)
            | Expr::Call(_, _, r)
            | Expr::Member(_, _, _, r)
            | Expr::At(_, _, r) => *r,
        }
    }
}

/// A syntax error: what is wrong and where, and for the mistakes people
/// bring from other languages, the label and the help that name the fix.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntaxError {
    pub message: String,
    pub range: Range,
    /// A short label at the place, when it differs from the message.
    pub label: Option<String>,
    /// The fix, when the parser knows it.
    pub help: Option<String>,
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Num(f64),
    Str(String),
    Ident(String),
    Sym(&'static str),
}

fn err<T>(message: impl Into<String>, range: Range) -> Result<T, SyntaxError> {
    Err(SyntaxError { message: message.into(), range, label: None, help: None })
}

fn hint<T>(message: impl Into<String>, range: Range, label: &str, help: impl Into<String>) -> Result<T, SyntaxError> {
    Err(SyntaxError { message: message.into(), range, label: Some(label.into()), help: Some(help.into()) })
}

/// The operators of other languages, with the word or operator of ours.
fn foreign(op: &str, range: Range) -> Result<(), SyntaxError> {
    match op {
        "=" => hint("`=` is not a comparison; write `==`", range, "write `==`", COMPARISONS),
        "=<" => hint("`=<` is not a comparison; write `<=`", range, "write `<=`", COMPARISONS),
        "=>" => hint("`=>` is not a comparison; write `>=`", range, "write `>=`", COMPARISONS),
        "<>" => hint("`<>` is not a comparison; write `!=`", range, "write `!=`", COMPARISONS),
        "&&" | "&" => hint(format!("`{op}` is written `and` in situ"), range, "write `and`", "write `and`"),
        "||" | "|" => hint(format!("`{op}` is written `or` in situ"), range, "write `or`", "write `or`"),
        "!" => hint("`!` is written `not` in situ", range, "write `not`", "write `not` and a space: `not ok`"),
        _ => Ok(()),
    }
}

const COMPARISONS: &str = "the comparisons are `==`, `!=`, `<`, `<=`, `>` and `>=`";

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
                let q = c as char;
                return hint(
                    "string without its closing quote",
                    (start, bytes.len()),
                    "not closed",
                    format!(
                        "close the string with the quote that opens it (`{q}`); in a TOML string, write the \
                         expression's strings in single quotes: `name == 'motor'`"
                    ),
                );
            }
            out.push((Tok::Str(text[start + 1..i].to_string()), (start, i + 1)));
            i += 1;
        } else {
            let two = text.get(i..i + 2).unwrap_or("");
            if let Some(op) = ["&&", "||", "=<", "=>", "<>"].into_iter().find(|s| *s == two) {
                foreign(op, (start, i + 2))?;
            }
            let sym = ["<=", ">=", "==", "!="].into_iter().find(|s| *s == two).or_else(|| {
                ["<", ">", "+", "-", "*", "/", "(", ")", "[", "]", ".", ","].into_iter().find(|s| s.as_bytes()[0] == c)
            });
            match sym {
                Some(s) => {
                    i += s.len();
                    out.push((Tok::Sym(s), (start, i)));
                }
                None => {
                    let ch = text[start..].chars().next().unwrap_or('?');
                    let range = (start, start + ch.len_utf8());
                    foreign(&text[range.0..range.1], range)?;
                    return err(format!("unexpected `{ch}`"), range);
                }
            }
        }
    }
    Ok(out)
}

struct Parser<'t> {
    text: &'t str,
    toks: Vec<(Tok, Range)>,
    pos: usize,
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
    let mut p = Parser { text, toks, pos: 0, depth: 0 };
    if p.toks.is_empty() {
        return err("empty expression", (0, text.len()));
    }
    let e = p.or()?;
    match p.toks.get(p.pos) {
        None => Ok(e),
        Some((Tok::Sym(","), r)) => hint(
            "`,` outside the arguments of a function",
            *r,
            "not in a function's arguments",
            "`,` separates the arguments of a function: `any(status, level >= 2)`",
        ),
        Some((_, r)) => err("unexpected text after the expression", (r.0, p.text.len())),
    }
}

impl Parser<'_> {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.pos).map(|(t, _)| t)
    }

    fn here(&self) -> Range {
        let end = self.text.len();
        self.toks.get(self.pos).map_or((end, end), |(_, r)| *r)
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

    fn cmp_op(&self) -> Option<BinOp> {
        Some(match self.peek() {
            Some(Tok::Sym("<")) => BinOp::Lt,
            Some(Tok::Sym("<=")) => BinOp::Le,
            Some(Tok::Sym(">")) => BinOp::Gt,
            Some(Tok::Sym(">=")) => BinOp::Ge,
            Some(Tok::Sym("==")) => BinOp::Eq,
            Some(Tok::Sym("!=")) => BinOp::Ne,
            _ => return None,
        })
    }

    fn cmp(&mut self) -> Result<Expr, SyntaxError> {
        let l = self.add()?;
        let Some(op) = self.cmp_op() else { return Ok(l) };
        self.pos += 1;
        let r = self.add()?;
        if let Some(op2) = self.cmp_op() {
            // `0 < x < 5`: comparisons do not chain.
            let second = self.here();
            self.pos += 1;
            let r2 = self.add()?;
            let part = |a: &Expr, b: &Expr| self.text.get(a.range().0..b.range().1).unwrap_or("…").to_string();
            let (first, then) = (part(&l, &r), part(&r, &r2));
            return hint(
                format!("comparisons do not chain: `{}` after `{}`", op2.text(), first),
                (second.0, r2.range().1),
                "a second comparison",
                format!("write `{first} and {then}`"),
            );
        }
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
                self.postfix(e)
            }
            Tok::Ident(w) if w == "true" || w == "false" => Ok(Expr::Bool(w == "true", range)),
            Tok::Ident(w) if matches!(w.as_str(), "and" | "or" | "not") => {
                err(format!("expected a value, found `{w}`"), range)
            }
            Tok::Ident(w) if self.is_sym("(") => {
                let call = self.call(&w, range)?;
                self.postfix(call)
            }
            Tok::Ident(w) => self.path(w, range),
            Tok::Sym(s) => err(format!("expected a value, found `{s}`"), range),
        }
    }

    /// The arguments of `name(`, then the call.
    fn call(&mut self, name: &str, range: Range) -> Result<Expr, SyntaxError> {
        let reducer = match name {
            "min" => Some(Reducer::Min),
            "max" => Some(Reducer::Max),
            "mean" => Some(Reducer::Mean),
            "len" => Some(Reducer::Len),
            _ => None,
        };
        let func = Func::of(name);
        if reducer.is_none() && func.is_none() {
            let help = match suggest(name, FUNCTIONS.iter().copied()) {
                Some(s) => format!("did you mean `{s}`? the functions are {}", FUNCTIONS.join(", ")),
                None => format!("the functions are {}", FUNCTIONS.join(", ")),
            };
            return hint(format!("`{name}` is not a function"), range, "unknown function", help);
        }
        self.pos += 1;
        self.deeper()?;
        let mut args = Vec::new();
        if !self.is_sym(")") {
            loop {
                args.push(self.or()?);
                if !self.is_sym(",") {
                    break;
                }
                self.pos += 1;
            }
        }
        self.depth -= 1;
        let close = match self.expect(")") {
            Ok(c) => c,
            Err(e) if self.peek().is_some() => {
                return Err(SyntaxError { message: format!("expected `,` or `)` in `{name}(…)`"), ..e })
            }
            Err(e) => return Err(e),
        };
        let whole = (range.0, close.1);
        match (reducer, func, args.len()) {
            (Some(r), _, 1) => Ok(Expr::Reduce(r, Box::new(args.remove(0)), whole)),
            (_, Some(f), n) if n == f.arity() => Ok(Expr::Call(f, args, whole)),
            (Some(Reducer::Len), _, n) => hint(
                format!("`len` takes 1 argument, found {n}"),
                whole,
                "`len(array)`",
                "`len(array)` is the number of elements; to count those that match, write `count(array, condition)`",
            ),
            (_, Some(f), n) => {
                let want = if reducer.is_some() { "1 or 2 arguments".to_string() } else { plural(f.arity()) };
                hint(format!("`{name}` takes {want}, found {n}"), whole, "wrong number of arguments", f.usage())
            }
            (Some(_), None, _) | (None, None, _) => err(format!("`{name}` is not a function"), range),
        }
    }

    /// A field path from its first name: `a.b[0]` as [`Expr::Path`], then
    /// what follows an index that is not a plain whole number.
    fn path(&mut self, first: String, range: Range) -> Result<Expr, SyntaxError> {
        let mut steps = vec![Step::Field(first, range)];
        let mut end = range.1;
        loop {
            if self.is_sym(".") {
                self.pos += 1;
                let (name, r) = self.field_name()?;
                end = r.1;
                steps.push(Step::Field(name, r));
            } else if self.is_sym("[") && self.literal_index().is_some() {
                let open = self.here().0;
                let index = self.literal_index().unwrap_or(0);
                self.pos += 2;
                let close = self.expect("]")?;
                end = close.1;
                steps.push(Step::Index(index, (open, close.1)));
            } else {
                break;
            }
        }
        self.postfix(Expr::Path(steps, (range.0, end)))
    }

    /// `[n]` ahead, with `n` a whole number written as such (`0`, not `0.0`).
    fn literal_index(&self) -> Option<u64> {
        let (Tok::Num(n), r) = self.toks.get(self.pos + 1)? else { return None };
        let written = self.text.get(r.0..r.1)?;
        let whole = written.bytes().all(|b| b.is_ascii_digit()) && (0.0..1e15).contains(n);
        let closed = matches!(self.toks.get(self.pos + 2), Some((Tok::Sym("]"), _)));
        (whole && closed).then_some(*n as u64)
    }

    fn field_name(&mut self) -> Result<(String, Range), SyntaxError> {
        match self.toks.get(self.pos).cloned() {
            Some((Tok::Ident(f), r)) => {
                self.pos += 1;
                Ok((f, r))
            }
            _ => err("expected a field name after `.`", self.here()),
        }
    }

    /// `.name` and `[index]` after a value.
    fn postfix(&mut self, mut e: Expr) -> Result<Expr, SyntaxError> {
        loop {
            let start = e.range().0;
            if self.is_sym(".") {
                self.pos += 1;
                let (name, r) = self.field_name()?;
                e = Expr::Member(Box::new(e), name, r, (start, r.1));
            } else if self.is_sym("[") {
                self.pos += 1;
                if self.is_sym("]") {
                    return hint(
                        "expected an index",
                        self.here(),
                        "no index",
                        "write the index of an element: `[0]` the first, `[-1]` the last",
                    );
                }
                self.deeper()?;
                let index = self.or()?;
                self.depth -= 1;
                let close = self.expect("]")?;
                e = Expr::At(Box::new(e), Box::new(index), (start, close.1));
            } else {
                return Ok(e);
            }
        }
    }
}

fn plural(n: usize) -> String {
    if n == 1 {
        "1 argument".into()
    } else {
        format!("{n} arguments")
    }
}

#[cfg(test)]
#[path = "expr_tests.rs"]
mod tests;
