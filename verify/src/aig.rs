//! And-inverter graphs: the symbolic form of the abstraction that
//! [`prove`](super::prove) closes and `situ export --aiger` writes.
//!
//! A literal is `2 × variable + negated`; variable 0 is the constant false,
//! so literal 0 is false and 1 is true. Variables are, in this order, the
//! inputs, the latches and the and-gates, as the AIGER format wants. Every
//! latch starts at 0. Gates are hashed structurally and simplified
//! (constants, `x ∧ x`, `x ∧ ¬x`), so the same condition is built once.

use std::collections::HashMap;
use std::fmt::Write as _;

pub type Lit = u32;
pub const FALSE: Lit = 0;
pub const TRUE: Lit = 1;

#[inline]
pub fn not(l: Lit) -> Lit {
    l ^ 1
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Node {
    Input,
    Latch,
    And(Lit, Lit),
}

/// A sequential circuit: inputs, latches (with their next-state literals)
/// and and-gates.
#[derive(Debug, Clone, Default)]
pub struct Aig {
    nodes: Vec<Node>,
    inputs: Vec<u32>,
    latches: Vec<u32>,
    next: Vec<Lit>,
    hash: HashMap<(Lit, Lit), Lit>,
    names: Vec<(bool, usize, String)>,
}

impl Aig {
    pub fn new() -> Aig {
        Aig { nodes: vec![Node::Input], ..Aig::default() }
    }

    pub fn input(&mut self, name: &str) -> Lit {
        let v = self.nodes.len() as u32;
        self.nodes.push(Node::Input);
        self.names.push((true, self.inputs.len(), name.to_string()));
        self.inputs.push(v);
        2 * v
    }

    /// A latch (initially 0); its next state is set with [`set_next`](Self::set_next).
    pub fn latch(&mut self, name: &str) -> Lit {
        let v = self.nodes.len() as u32;
        self.nodes.push(Node::Latch);
        self.names.push((false, self.latches.len(), name.to_string()));
        self.latches.push(v);
        self.next.push(FALSE);
        2 * v
    }

    pub fn set_next(&mut self, latch: Lit, next: Lit) {
        let i = self.latches.iter().position(|&v| 2 * v == latch).expect("a latch");
        self.next[i] = next;
    }

    pub fn and(&mut self, a: Lit, b: Lit) -> Lit {
        let (a, b) = if a < b { (a, b) } else { (b, a) };
        if a == FALSE || a == not(b) {
            return FALSE;
        }
        if a == TRUE || a == b {
            return b;
        }
        if let Some(&l) = self.hash.get(&(a, b)) {
            return l;
        }
        let v = self.nodes.len() as u32;
        self.nodes.push(Node::And(a, b));
        self.hash.insert((a, b), 2 * v);
        2 * v
    }

    pub fn or(&mut self, a: Lit, b: Lit) -> Lit {
        let n = self.and(not(a), not(b));
        not(n)
    }

    pub fn and_all(&mut self, ls: impl IntoIterator<Item = Lit>) -> Lit {
        ls.into_iter().fold(TRUE, |acc, l| self.and(acc, l))
    }

    pub fn or_all(&mut self, ls: impl IntoIterator<Item = Lit>) -> Lit {
        ls.into_iter().fold(FALSE, |acc, l| self.or(acc, l))
    }

    /// `c ? t : e`.
    pub fn mux(&mut self, c: Lit, t: Lit, e: Lit) -> Lit {
        let a = self.and(c, t);
        let b = self.and(not(c), e);
        self.or(a, b)
    }

    pub fn xor(&mut self, a: Lit, b: Lit) -> Lit {
        let x = self.and(a, not(b));
        let y = self.and(not(a), b);
        self.or(x, y)
    }

    pub fn inputs(&self) -> &[u32] {
        &self.inputs
    }

    pub fn latches(&self) -> &[u32] {
        &self.latches
    }

    pub fn next_of(&self, i: usize) -> Lit {
        self.next[i]
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.len() <= 1
    }

    /// The and-gate of a variable, if it is one.
    pub fn gate(&self, var: u32) -> Option<(Lit, Lit)> {
        match self.nodes[var as usize] {
            Node::And(a, b) => Some((a, b)),
            _ => None,
        }
    }

    /// Evaluates every variable for these input and latch values.
    pub fn eval(&self, inputs: &[bool], latches: &[bool]) -> Vec<bool> {
        let mut val = vec![false; self.nodes.len()];
        for (i, &v) in self.inputs.iter().enumerate() {
            val[v as usize] = inputs[i];
        }
        for (i, &v) in self.latches.iter().enumerate() {
            val[v as usize] = latches[i];
        }
        for (v, n) in self.nodes.iter().enumerate() {
            if let Node::And(a, b) = *n {
                val[v] = lit_value(&val, a) && lit_value(&val, b);
            }
        }
        val
    }

    /// AIGER's numbering of our variables (inputs, then latches, then
    /// gates; ours are mixed), and the gates in order.
    fn numbering(&self) -> (Vec<u32>, Vec<u32>) {
        let mut map = vec![0u32; self.nodes.len()];
        let mut k = 1u32;
        for &v in self.inputs.iter().chain(&self.latches) {
            map[v as usize] = k;
            k += 1;
        }
        let gates: Vec<u32> =
            (0..self.nodes.len() as u32).filter(|&v| matches!(self.nodes[v as usize], Node::And(..))).collect();
        for &v in &gates {
            map[v as usize] = k;
            k += 1;
        }
        (map, gates)
    }

    /// The circuit in the binary AIGER 1.9 format, `bad` as its bad-state
    /// properties (named in the symbol table).
    pub fn to_aig(&self, bad: &[(String, Lit)]) -> Vec<u8> {
        let (map, gates) = self.numbering();
        let k = map.iter().max().copied().unwrap_or(0) + 1;
        let m = |l: Lit| 2 * map[(l >> 1) as usize] + (l & 1);
        let mut out =
            format!("aig {} {} {} 0 {} {}\n", k - 1, self.inputs.len(), self.latches.len(), gates.len(), bad.len())
                .into_bytes();
        for i in 0..self.latches.len() {
            out.extend(format!("{}\n", m(self.next[i])).bytes());
        }
        for (_, l) in bad {
            out.extend(format!("{}\n", m(*l)).bytes());
        }
        let varint = |out: &mut Vec<u8>, mut x: u32| {
            while x & !0x7f != 0 {
                out.push((x & 0x7f) as u8 | 0x80);
                x >>= 7;
            }
            out.push(x as u8);
        };
        for &v in &gates {
            if let Node::And(a, b) = self.nodes[v as usize] {
                let lhs = m(2 * v);
                let (r0, r1) = (m(a).max(m(b)), m(a).min(m(b)));
                varint(&mut out, lhs - r0);
                varint(&mut out, r0 - r1);
            }
        }
        let mut sym = String::new();
        for (input, i, name) in &self.names {
            let _ = writeln!(sym, "{}{} {}", if *input { 'i' } else { 'l' }, i, name.replace('\n', " "));
        }
        for (i, (name, _)) in bad.iter().enumerate() {
            let _ = writeln!(sym, "b{i} {}", name.replace('\n', " "));
        }
        sym.push_str("c\nsitu: the abstraction of `situ test`, one bad-state output per property\n");
        out.extend(sym.bytes());
        out
    }

    /// The circuit in the AIGER 1.9 ASCII format, `bad` as its bad-state
    /// properties (one per line, named in the symbol table).
    pub fn to_aag(&self, bad: &[(String, Lit)]) -> String {
        let (map, gates) = self.numbering();
        let k = map.iter().max().copied().unwrap_or(0) + 1;
        let m = |l: Lit| 2 * map[(l >> 1) as usize] + (l & 1);
        let mut out = String::new();
        let _ =
            writeln!(out, "aag {} {} {} 0 {} {}", k - 1, self.inputs.len(), self.latches.len(), gates.len(), bad.len());
        for &v in &self.inputs {
            let _ = writeln!(out, "{}", m(2 * v));
        }
        for (i, &v) in self.latches.iter().enumerate() {
            let _ = writeln!(out, "{} {}", m(2 * v), m(self.next[i]));
        }
        for (_, l) in bad {
            let _ = writeln!(out, "{}", m(*l));
        }
        for &v in &gates {
            if let Node::And(a, b) = self.nodes[v as usize] {
                let (a, b) = (m(a), m(b));
                let (a, b) = if a >= b { (a, b) } else { (b, a) };
                let _ = writeln!(out, "{} {} {}", m(2 * v), a, b);
            }
        }
        for (input, i, name) in &self.names {
            let _ = writeln!(out, "{}{} {}", if *input { 'i' } else { 'l' }, i, name.replace('\n', " "));
        }
        for (i, (name, _)) in bad.iter().enumerate() {
            let _ = writeln!(out, "b{i} {}", name.replace('\n', " "));
        }
        out.push_str("c\nsitu: the abstraction of `situ test`, one bad-state output per property\n");
        out
    }
}

#[inline]
pub fn lit_value(val: &[bool], l: Lit) -> bool {
    val[(l >> 1) as usize] ^ (l & 1 == 1)
}

/// A number in binary on some literals (least significant first).
#[derive(Debug, Clone, Default)]
pub struct Word {
    pub bits: Vec<Lit>,
}

/// How many bits hold the numbers `0..=max`.
pub fn bits_upto(max: u64) -> usize {
    (u64::BITS - max.leading_zeros()) as usize
}

/// How many bits hold the numbers `0..n`.
pub fn width(n: usize) -> usize {
    let mut w = 0;
    while (1usize << w) < n {
        w += 1;
    }
    w
}

impl Word {
    pub fn latches(aig: &mut Aig, name: &str, n: usize) -> Word {
        Word { bits: (0..width(n)).map(|i| aig.latch(&format!("{name}[{i}]"))).collect() }
    }

    pub fn inputs(aig: &mut Aig, name: &str, n: usize) -> Word {
        Word { bits: (0..width(n)).map(|i| aig.input(&format!("{name}[{i}]"))).collect() }
    }

    /// Latches for the numbers `0..=max`.
    pub fn latches_upto(aig: &mut Aig, name: &str, max: u64) -> Word {
        Word { bits: (0..bits_upto(max)).map(|i| aig.latch(&format!("{name}[{i}]"))).collect() }
    }

    /// Inputs for the numbers `0..=max`.
    pub fn inputs_upto(aig: &mut Aig, name: &str, max: u64) -> Word {
        Word { bits: (0..bits_upto(max)).map(|i| aig.input(&format!("{name}[{i}]"))).collect() }
    }

    pub fn constant(k: usize, w: usize) -> Word {
        Word { bits: (0..w).map(|i| if i < usize::BITS as usize && k >> i & 1 == 1 { TRUE } else { FALSE }).collect() }
    }

    /// Whether the word holds `k`.
    pub fn eq(&self, aig: &mut Aig, k: usize) -> Lit {
        if k >> self.bits.len() != 0 {
            return FALSE;
        }
        let ls: Vec<Lit> =
            self.bits.iter().enumerate().map(|(i, &b)| if k >> i & 1 == 1 { b } else { not(b) }).collect();
        aig.and_all(ls)
    }

    /// One literal per value `0..n`: whether the word holds it, values at
    /// or above `n` read as 0.
    pub fn decode(&self, aig: &mut Aig, n: usize) -> Vec<Lit> {
        let mut sel: Vec<Lit> = (0..n).map(|k| self.eq(aig, k)).collect();
        if n > 0 && (1usize << self.bits.len()) > n {
            let others = aig.or_all(sel[1..].iter().copied());
            sel[0] = not(others);
        }
        sel
    }

    /// The word of `cases` (condition, value), the conditions exclusive;
    /// 0 where none holds.
    pub fn select(aig: &mut Aig, w: usize, cases: &[(Lit, usize)]) -> Word {
        let bits = (0..w)
            .map(|i| {
                let ls: Vec<Lit> = cases.iter().filter(|(_, k)| k >> i & 1 == 1).map(|(c, _)| *c).collect();
                aig.or_all(ls)
            })
            .collect();
        Word { bits }
    }

    /// `c ? a : b`, bit by bit.
    pub fn mux(aig: &mut Aig, c: Lit, a: &Word, b: &Word) -> Word {
        Word { bits: a.bits.iter().zip(&b.bits).map(|(&x, &y)| aig.mux(c, x, y)).collect() }
    }

    /// `self + other`, one bit wider than the wider of the two.
    pub fn add(&self, aig: &mut Aig, other: &Word) -> Word {
        let w = self.bits.len().max(other.bits.len());
        let mut carry = FALSE;
        let mut bits = Vec::with_capacity(w + 1);
        for i in 0..w {
            let a = self.bits.get(i).copied().unwrap_or(FALSE);
            let b = other.bits.get(i).copied().unwrap_or(FALSE);
            let ab = aig.xor(a, b);
            bits.push(aig.xor(ab, carry));
            let both = aig.and(a, b);
            let through = aig.and(ab, carry);
            carry = aig.or(both, through);
        }
        bits.push(carry);
        Word { bits }
    }

    /// Whether the number is greater than `k`.
    pub fn gt(&self, aig: &mut Aig, k: u64) -> Lit {
        // From the least significant bit up: greater on bits 0..=i.
        let mut gt = FALSE;
        for (i, &b) in self.bits.iter().enumerate() {
            let kb = i < 64 && k >> i & 1 == 1;
            gt = if kb { aig.and(b, gt) } else { aig.or(b, gt) };
        }
        // Bits of k above the word: the word is smaller.
        if self.bits.len() < 64 && k >> self.bits.len() != 0 {
            FALSE
        } else {
            gt
        }
    }

    /// `min(self, k)` on `w` bits (`k` must fit).
    pub fn min_const(&self, aig: &mut Aig, k: u64, w: usize) -> Word {
        let over = self.gt(aig, k);
        let cap = Word::constant(k as usize, w);
        let mut low = self.bits.clone();
        low.resize(w, FALSE);
        Word::mux(aig, over, &cap, &Word { bits: low })
    }

    /// The number these bits hold.
    pub fn value(&self, val: &[bool]) -> usize {
        self.bits.iter().enumerate().map(|(i, &b)| (lit_value(val, b) as usize) << i).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gates_are_shared_and_simplified() {
        let mut g = Aig::new();
        let a = g.input("a");
        let b = g.input("b");
        let x = g.and(a, b);
        assert_eq!(g.and(b, a), x);
        assert_eq!(g.and(a, not(a)), FALSE);
        assert_eq!(g.and(a, TRUE), a);
        let w = Word { bits: vec![a, b] };
        let three = w.eq(&mut g, 3);
        assert_eq!(three, x);
        let v = g.eval(&[true, true], &[]);
        assert!(lit_value(&v, three));
    }

    #[test]
    fn arithmetic_on_words_is_exact() {
        let mut g = Aig::new();
        let x = Word::inputs(&mut g, "x", 16);
        let y = Word::inputs(&mut g, "y", 8);
        let sum = x.add(&mut g, &y);
        let capped = sum.min_const(&mut g, 9, 4);
        let over5 = x.gt(&mut g, 5);
        for a in 0..16usize {
            for b in 0..8usize {
                let ins: Vec<bool> = (0..4).map(|i| a >> i & 1 == 1).chain((0..3).map(|i| b >> i & 1 == 1)).collect();
                let v = g.eval(&ins, &[]);
                assert_eq!(sum.value(&v), a + b);
                assert_eq!(capped.value(&v), (a + b).min(9));
                assert_eq!(lit_value(&v, over5), a > 5);
            }
        }
    }

    #[test]
    fn aiger_text_counts_its_parts() {
        let mut g = Aig::new();
        let i = g.input("go");
        let l = g.latch("on");
        let n = g.or(i, l);
        g.set_next(l, n);
        let text = g.to_aag(&[("on".into(), l)]);
        assert!(text.starts_with("aag 3 1 1 0 1 1\n2\n4 7\n4\n6 5 3\n"), "{text}");
    }
}
