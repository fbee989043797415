//! The exact nearest-neighbour index of a case base (see `cases.rs`).
//!
//! The keys are held in single precision. Most of them sit in a few static
//! k-d trees, each built at once over its keys: every node splits its keys
//! along the dimension where they spread most (not in turn, as kiddo's
//! trees do: a robot's situations spread very unevenly, many ranges at the
//! maximum), near the middle of that spread (the rank kept between the
//! quartiles); the leaves (at most [`LEAF`] keys) are stored one after the
//! other, dimension by dimension in groups of [`LANES`] keys, so that a
//! leaf is scanned eight keys at a time (with AVX when the processor has
//! it). The search descends to the query's leaf first, then visits a
//! subtree only when the distance from the query to its cell (kept
//! incrementally, Arya and Mount 1993) is below the best distance found so
//! far; it starts from each tree's bounding box. It is exact: no subtree
//! that may hold a nearer key is skipped.
//!
//! The keys added since the last build are kept in a small buffer
//! ([`BUFFER`] keys) that is scanned in full. When it is full, it becomes a
//! tree of its own, and the last tree is merged (rebuilt) with the one
//! before while it holds more than a [`RATIO`]th of that one's keys: the
//! trees' sizes fall by at least that ratio, so there are few of them (a
//! logarithmic method, Bentley and Saxe 1980), an addition costs a few
//! microseconds amortised, and a search carries its best distance from the
//! largest tree to the smaller ones, which it mostly prunes at once.
//! [`Index::compact`] merges everything into one tree.

/// Keys compared at once in a leaf scan.
const LANES: usize = 8;
/// The largest number of keys in a leaf (a multiple of [`LANES`]).
const LEAF: usize = 64;
/// Keys kept in the scanned buffer before they become a tree.
const BUFFER: usize = 128;
/// The smallest ratio between the sizes of consecutive trees.
const RATIO: usize = 8;
/// The `dim` of a leaf node.
const LEAF_NODE: u32 = u32::MAX;
/// The id of a padding slot.
const NONE: u32 = u32::MAX;

/// [`LANES`] keys, dimension by dimension; a slot without a key holds
/// infinities (its distance is infinite, never the nearest).
type Chunk<const D: usize> = [[f32; LANES]; D];

/// A node of a tree: a leaf (chunks `a..b`), or a split on `dim` at
/// `split` (keys at most `split` in child `a`, at least `split` in child `b`).
#[derive(Debug, Clone, Copy)]
struct Node {
    split: f32,
    dim: u32,
    a: u32,
    b: u32,
}

/// The best key found so far: its squared distance and id.
struct Best {
    d2: f32,
    id: u32,
}

/// The distances from a query to the keys of a chunk, into `best`.
#[inline(always)]
fn scan<const D: usize>(chunk: &Chunk<D>, ids: &[u32], q: &[f32; D], best: &mut Best) {
    let mut acc = [0.0f32; LANES];
    for (c, &qd) in chunk.iter().zip(q) {
        for (a, &x) in acc.iter_mut().zip(c) {
            let t = x - qd;
            *a += t * t;
        }
    }
    let min = acc.iter().copied().fold(f32::INFINITY, f32::min);
    if min < best.d2 {
        for (&a, &id) in acc.iter().zip(ids) {
            if a < best.d2 {
                best.d2 = a;
                best.id = id;
            }
        }
    }
}

/// The distances from a query to the keys of some chunks, into `best`:
/// with AVX (eight lanes at once) when the processor has it.
#[inline]
fn scan_leaf<const D: usize>(chunks: &[Chunk<D>], ids: &[u32], q: &[f32; D], best: &mut Best) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the processor has AVX.
        unsafe { scan_leaf_avx(chunks, ids, q, best) };
        return;
    }
    scan_leaf_portable(chunks, ids, q, best);
}

/// [`scan_leaf`] compiled for AVX.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn scan_leaf_avx<const D: usize>(chunks: &[Chunk<D>], ids: &[u32], q: &[f32; D], best: &mut Best) {
    scan_leaf_portable(chunks, ids, q, best);
}

/// [`scan_leaf`] for any processor.
#[inline(always)]
fn scan_leaf_portable<const D: usize>(chunks: &[Chunk<D>], ids: &[u32], q: &[f32; D], best: &mut Best) {
    for (chunk, ids) in chunks.iter().zip(ids.chunks_exact(LANES)) {
        scan(chunk, ids, q, best);
    }
}

/// A static k-d tree over some keys.
#[derive(Debug, Clone)]
struct Tree<const D: usize> {
    /// The nodes, the root first.
    nodes: Vec<Node>,
    /// The leaves' keys.
    chunks: Vec<Chunk<D>>,
    /// The id of each slot of `chunks` ([`NONE`] for padding).
    ids: Vec<u32>,
    /// The bounding box of the keys.
    lo: [f32; D],
    hi: [f32; D],
    /// Number of keys.
    len: usize,
}

impl<const D: usize> Tree<D> {
    /// A tree over the keys `ids` of `keys` (at least one).
    fn build(keys: &[[f32; D]], mut ids: Vec<u32>) -> Self {
        let (lo, hi) = bounds(keys, &ids);
        let mut t = Tree {
            nodes: Vec::with_capacity(2 * ids.len() / (LEAF / 2) + 1),
            chunks: Vec::with_capacity(ids.len() / LANES + ids.len() / LEAF + 1),
            ids: Vec::new(),
            lo,
            hi,
            len: ids.len(),
        };
        t.node(keys, &mut ids);
        t
    }

    /// Builds the subtree over `ids`; its index.
    fn node(&mut self, keys: &[[f32; D]], ids: &mut [u32]) -> u32 {
        let index = self.nodes.len();
        self.nodes.push(Node { split: 0.0, dim: LEAF_NODE, a: 0, b: 0 });
        if ids.len() <= LEAF {
            let first = self.chunks.len() as u32;
            for group in ids.chunks(LANES) {
                let mut chunk = [[f32::INFINITY; LANES]; D];
                for (lane, &id) in group.iter().enumerate() {
                    for (c, &k) in chunk.iter_mut().zip(&keys[id as usize]) {
                        c[lane] = k;
                    }
                }
                self.chunks.push(chunk);
                self.ids.extend_from_slice(group);
                self.ids.resize(self.chunks.len() * LANES, NONE);
            }
            self.nodes[index] = Node { split: 0.0, dim: LEAF_NODE, a: first, b: self.chunks.len() as u32 };
            return index as u32;
        }
        let (lo, hi) = bounds(keys, ids);
        let dim = (0..D).max_by(|&i, &j| (hi[i] - lo[i]).total_cmp(&(hi[j] - lo[j]))).unwrap_or(0);
        // The rank of the middle of the spread, kept between the quartiles
        // and rounded to whole chunks on the low side.
        let middle = (lo[dim] + hi[dim]) / 2.0;
        let below = ids.iter().filter(|&&id| keys[id as usize][dim] < middle).count();
        let mid = below.clamp(ids.len() / 4, ids.len() * 3 / 4).div_ceil(LANES) * LANES;
        let mid = mid.clamp(LANES, ids.len() - 1);
        ids.select_nth_unstable_by(mid, |&a, &b| keys[a as usize][dim].total_cmp(&keys[b as usize][dim]));
        let split = keys[ids[mid] as usize][dim];
        let (low, high) = ids.split_at_mut(mid);
        let a = self.node(keys, low);
        let b = self.node(keys, high);
        self.nodes[index] = Node { split, dim: dim as u32, a, b };
        index as u32
    }

    /// The ids of the keys.
    fn ids(&self) -> impl Iterator<Item = u32> + '_ {
        self.ids.iter().copied().filter(|&id| id != NONE)
    }

    /// Looks for a key nearer to `q` than `best`.
    fn search(&self, q: &[f32; D], best: &mut Best) {
        let mut off = [0.0f32; D];
        let mut rd = 0.0f32;
        for (((o, &x), &lo), &hi) in off.iter_mut().zip(q).zip(&self.lo).zip(&self.hi) {
            *o = (lo - x).max(x - hi).max(0.0);
            rd += *o * *o;
        }
        if rd < best.d2 {
            self.visit(0, q, rd, &mut off, best);
        }
    }

    /// The search in the subtree `n`, whose cell is at squared distance
    /// `rd` from `q`, `off` being the offsets along each dimension.
    fn visit(&self, n: u32, q: &[f32; D], rd: f32, off: &mut [f32; D], best: &mut Best) {
        let node = self.nodes[n as usize];
        if node.dim == LEAF_NODE {
            let (a, b) = (node.a as usize, node.b as usize);
            scan_leaf(&self.chunks[a..b], &self.ids[a * LANES..b * LANES], q, best);
            return;
        }
        let dim = node.dim as usize;
        let d = q[dim] - node.split;
        let (near, far) = if d < 0.0 { (node.a, node.b) } else { (node.b, node.a) };
        self.visit(near, q, rd, off, best);
        let old = off[dim];
        let far_rd = rd - old * old + d * d;
        if far_rd < best.d2 {
            off[dim] = d;
            self.visit(far, q, far_rd, off, best);
            off[dim] = old;
        }
    }
}

/// The bounding box of the keys `ids` of `keys`.
fn bounds<const D: usize>(keys: &[[f32; D]], ids: &[u32]) -> ([f32; D], [f32; D]) {
    let mut lo = [f32::INFINITY; D];
    let mut hi = [f32::NEG_INFINITY; D];
    for &id in ids {
        for ((l, h), &k) in lo.iter_mut().zip(hi.iter_mut()).zip(&keys[id as usize]) {
            *l = l.min(k);
            *h = h.max(k);
        }
    }
    (lo, hi)
}

/// The exact nearest-neighbour index: the keys by id (in the order they were
/// added), the trees (largest first) and the buffer of the latest keys.
#[derive(Debug, Clone)]
pub(super) struct Index<const D: usize> {
    keys: Vec<[f32; D]>,
    trees: Vec<Tree<D>>,
    buffer: Vec<Chunk<D>>,
    buffer_ids: Vec<u32>,
}

impl<const D: usize> Default for Index<D> {
    fn default() -> Self {
        Index { keys: Vec::new(), trees: Vec::new(), buffer: Vec::new(), buffer_ids: Vec::new() }
    }
}

impl<const D: usize> Index<D> {
    /// Adds a key (finite); its id is the number of keys added before.
    pub(super) fn add(&mut self, key: [f32; D]) {
        let id = self.keys.len() as u32;
        self.keys.push(key);
        let slot = self.buffer_ids.len();
        if slot == self.buffer.len() * LANES {
            self.buffer.push([[f32::INFINITY; LANES]; D]);
        }
        let chunk = &mut self.buffer[slot / LANES];
        for (c, &k) in chunk.iter_mut().zip(&key) {
            c[slot % LANES] = k;
        }
        self.buffer_ids.push(id);
        if self.buffer_ids.len() >= BUFFER {
            let ids = std::mem::take(&mut self.buffer_ids);
            self.buffer.clear();
            self.trees.push(Tree::build(&self.keys, ids));
            while let [.., before, last] = self.trees.as_slice() {
                if last.len * RATIO <= before.len {
                    break;
                }
                let last = self.trees.pop().expect("two trees");
                let before = self.trees.pop().expect("two trees");
                let ids = before.ids().chain(last.ids()).collect();
                self.trees.push(Tree::build(&self.keys, ids));
            }
        }
    }

    /// Puts every key into one tree.
    pub(super) fn compact(&mut self) {
        if self.trees.len() + usize::from(!self.buffer_ids.is_empty()) > 1 {
            let mut ids: Vec<u32> = self.trees.iter().flat_map(Tree::ids).collect();
            ids.append(&mut self.buffer_ids);
            self.buffer.clear();
            self.trees = vec![Tree::build(&self.keys, ids)];
        }
    }

    /// The id of the key nearest to `q` (single precision; between keys at
    /// equal distances, either), `None` when there is none.
    pub(super) fn nearest(&self, q: &[f32; D]) -> Option<usize> {
        let mut best = Best { d2: f32::INFINITY, id: NONE };
        for t in &self.trees {
            t.search(q, &mut best);
        }
        for (c, chunk) in self.buffer.iter().enumerate() {
            let ids = &self.buffer_ids[c * LANES..self.buffer_ids.len().min((c + 1) * LANES)];
            scan(chunk, ids, q, &mut best);
        }
        (best.id != NONE).then_some(best.id as usize)
    }
}
