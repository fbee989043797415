//! The topological layer of DLA: the hierarchical pyramid by split and merge
//! over an occupancy grid (Poncela et al. 2002), and the homogeneous regions
//! it yields, which are the topological map.
//!
//! 1. **Generation.** The pyramid is built bottom-up as a quadtree over the
//!    grid padded to a power of two: level 0 holds the cells, a node of
//!    level `l + 1` the four nodes of level `l` below it. A node keeps the
//!    minimum, maximum and sum of its cells' occupancy probabilities and the
//!    classes present (free, occupied, unknown by the grid's thresholds). It
//!    is *homogeneous* when its children are, all its cells have one class
//!    and the spread `max − min` is at most [`PyramidParams::spread`].
//! 2. **Pruning.** Inhomogeneous nodes are removed; the homogeneous nodes
//!    whose parent was removed (or the root, if homogeneous) are *orphans*:
//!    square blocks of cells that partition the grid.
//! 3. **Merging.** Each orphan links to a neighbouring orphan (a sibling at
//!    its own level, or a node of an upper level) that shares an edge of
//!    cells with it, has its class and an occupancy similar to that of the
//!    region it already belongs to (within [`PyramidParams::merge`]).
//!    Links are tried larger blocks first, so rooms form before doors; a
//!    link is refused when the region's bounding box would exceed
//!    [`PyramidParams::max_extent`] cells, which keeps regions of a size
//!    worth planning over.
//! 4. **Topology.** The linked sets of orphans are the regions: free,
//!    occupied or unexplored, each with its cells, blocks, bounding box,
//!    centroid and mean occupancy; two regions are adjacent when a cell of
//!    one shares an edge with a cell of the other. The links between both
//!    representations are kept: cell → region ([`Pyramid::region_of`]) and
//!    region → cells ([`Pyramid::cells`]).
//!
//! Everything is deterministic and linear in the number of cells, but for
//! sorting the links between blocks.

use super::grid::{CellClass, OccupancyGrid};
use situ_sim::geom::{v2, Vec2};

/// The thresholds of the split and merge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PyramidParams {
    /// Largest spread of occupancy probability inside a homogeneous node.
    pub spread: f64,
    /// Largest difference of mean occupancy between an orphan and the
    /// region it links to.
    pub merge: f64,
    /// Largest side (cells) of the bounding box of a region made by links;
    /// 0 for no limit. A single orphan block larger than this stays whole.
    pub max_extent: usize,
}

impl Default for PyramidParams {
    fn default() -> Self {
        PyramidParams { spread: 0.2, merge: 0.15, max_extent: 64 }
    }
}

/// What a region of the topological map is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum RegionClass {
    /// Explored and free: the robot may go there.
    Free,
    /// Explored and occupied: an obstacle.
    Occupied,
    /// Not (well enough) explored.
    Unexplored,
}

impl From<CellClass> for RegionClass {
    fn from(c: CellClass) -> Self {
        match c {
            CellClass::Free => RegionClass::Free,
            CellClass::Occupied => RegionClass::Occupied,
            CellClass::Unknown => RegionClass::Unexplored,
        }
    }
}

/// An orphan node of the pruned pyramid: a square block of cells (clipped
/// to the grid) that is homogeneous.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Block {
    /// Level in the pyramid (0: one cell; `l`: `2^l × 2^l` cells).
    pub level: u8,
    /// Column of the block's first cell.
    pub x: u32,
    /// Row of the block's first cell.
    pub y: u32,
    /// Number of columns inside the grid.
    pub w: u32,
    /// Number of rows inside the grid.
    pub h: u32,
    /// Mean occupancy probability of its cells.
    pub mean: f64,
    /// Class of its cells.
    pub class: RegionClass,
    /// The region it was linked into.
    pub region: usize,
}

/// A rectangle of cells, bounds inclusive.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CellBox {
    /// Lowest column.
    pub x0: usize,
    /// Lowest row.
    pub y0: usize,
    /// Highest column.
    pub x1: usize,
    /// Highest row.
    pub y1: usize,
}

impl CellBox {
    fn union(&self, o: &CellBox) -> CellBox {
        CellBox { x0: self.x0.min(o.x0), y0: self.y0.min(o.y0), x1: self.x1.max(o.x1), y1: self.y1.max(o.y1) }
    }
    /// Whether cell `(x, y)` lies inside.
    pub fn contains(&self, x: usize, y: usize) -> bool {
        x >= self.x0 && x <= self.x1 && y >= self.y0 && y <= self.y1
    }
}

/// A homogeneous region: a node of the topological map.
#[derive(Debug, Clone, PartialEq)]
pub struct Region {
    /// Its index in [`Pyramid::regions`].
    pub id: usize,
    /// Free, occupied or unexplored.
    pub class: RegionClass,
    /// Number of cells.
    pub size: usize,
    /// Bounding box of its cells.
    pub bbox: CellBox,
    /// Mean of its cells' centres (m).
    pub centroid: Vec2,
    /// Mean occupancy probability of its cells.
    pub mean_occupancy: f64,
    /// Indices in [`Pyramid::blocks`] of the orphans linked into it.
    pub blocks: Vec<usize>,
}

/// The pruned and merged pyramid of a grid: its orphan blocks, regions,
/// region adjacency and the links between cells and regions.
#[derive(Debug, Clone)]
pub struct Pyramid {
    width: usize,
    height: usize,
    levels: usize,
    blocks: Vec<Block>,
    regions: Vec<Region>,
    cell_region: Vec<u32>,
    region_cells: Vec<u32>,
    cell_start: Vec<usize>,
    adjacency: Vec<Vec<usize>>,
}

/// Statistics of the nodes of one level, by node index `j·side + i`.
struct Level {
    side: usize,
    min: Vec<f32>,
    max: Vec<f32>,
    sum: Vec<f32>,
    count: Vec<u32>,
    /// Bits of the classes present (1 free, 2 occupied, 4 unknown); bit 7
    /// set when the node is not homogeneous.
    mask: Vec<u8>,
}

const INHOMOGENEOUS: u8 = 0x80;

fn class_bit(c: CellClass) -> u8 {
    match c {
        CellClass::Free => 1,
        CellClass::Occupied => 2,
        CellClass::Unknown => 4,
    }
}

fn class_of_bit(b: u8) -> RegionClass {
    match b {
        1 => RegionClass::Free,
        2 => RegionClass::Occupied,
        _ => RegionClass::Unexplored,
    }
}

fn find(parent: &mut [u32], mut a: u32) -> u32 {
    while parent[a as usize] != a {
        let g = parent[parent[a as usize] as usize];
        parent[a as usize] = g;
        a = g;
    }
    a
}

impl Pyramid {
    /// Builds the pyramid of `grid`, prunes it, links its orphans and
    /// derives the regions and their adjacency.
    pub fn build(grid: &OccupancyGrid, params: &PyramidParams) -> Pyramid {
        let (w, h) = (grid.width(), grid.height());
        let side = w.max(h).next_power_of_two();
        let levels = side.trailing_zeros() as usize + 1;

        // 1. Generation, bottom-up.
        let mut pyr: Vec<Level> = Vec::with_capacity(levels);
        let n0 = side * side;
        let mut base = Level {
            side,
            min: vec![0.0; n0],
            max: vec![0.0; n0],
            sum: vec![0.0; n0],
            count: vec![0; n0],
            mask: vec![0; n0],
        };
        let lo = grid.logodds_cells();
        // Neighbouring cells often hold the same log-odds (unknown, or
        // clamped): the last probability and class computed are reused.
        let (mut last_l, mut last_p, mut last_class) = (0.0f32, 0.5f32, grid.classify(0.5));
        for y in 0..h {
            for x in 0..w {
                let l = lo[y * w + x];
                if l.to_bits() != last_l.to_bits() {
                    let p = super::grid::probability(l);
                    (last_l, last_p, last_class) = (l, p as f32, grid.classify(p));
                }
                let (p, class) = (last_p, last_class);
                let j = y * side + x;
                base.min[j] = p;
                base.max[j] = p;
                base.sum[j] = p;
                base.count[j] = 1;
                base.mask[j] = class_bit(class);
            }
        }
        pyr.push(base);
        let spread = params.spread as f32;
        for _ in 1..levels {
            let below = pyr.last().expect("level 0 exists");
            let s = below.side / 2;
            let mut up = Level {
                side: s,
                min: vec![f32::INFINITY; s * s],
                max: vec![f32::NEG_INFINITY; s * s],
                sum: vec![0.0; s * s],
                count: vec![0; s * s],
                mask: vec![0; s * s],
            };
            for j in 0..s {
                for i in 0..s {
                    let u = j * s + i;
                    let mut mask = 0u8;
                    for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let c = (2 * j + dj) * below.side + 2 * i + di;
                        if below.count[c] == 0 {
                            continue;
                        }
                        mask |= below.mask[c];
                        up.min[u] = up.min[u].min(below.min[c]);
                        up.max[u] = up.max[u].max(below.max[c]);
                        up.sum[u] += below.sum[c];
                        up.count[u] += below.count[c];
                    }
                    let classes = mask & !INHOMOGENEOUS;
                    if mask & INHOMOGENEOUS != 0 || classes.count_ones() > 1 || up.max[u] - up.min[u] > spread {
                        mask |= INHOMOGENEOUS;
                    }
                    up.mask[u] = mask;
                }
            }
            pyr.push(up);
        }

        // 2. Pruning: the orphans, top-down (a deterministic order).
        let mut blocks: Vec<Block> = Vec::new();
        let mut stack = vec![(levels - 1, 0usize, 0usize)];
        while let Some((l, i, j)) = stack.pop() {
            let lv = &pyr[l];
            let u = j * lv.side + i;
            if lv.count[u] == 0 {
                continue;
            }
            if lv.mask[u] & INHOMOGENEOUS == 0 {
                let (x, y) = (i << l, j << l);
                let bw = (1usize << l).min(w - x);
                let bh = (1usize << l).min(h - y);
                blocks.push(Block {
                    level: l as u8,
                    x: x as u32,
                    y: y as u32,
                    w: bw as u32,
                    h: bh as u32,
                    mean: lv.sum[u] as f64 / lv.count[u] as f64,
                    class: class_of_bit(lv.mask[u]),
                    region: 0,
                });
            } else {
                // Children pushed in reverse so that they pop in order.
                for (di, dj) in [(1, 1), (0, 1), (1, 0), (0, 0)] {
                    stack.push((l - 1, 2 * i + di, 2 * j + dj));
                }
            }
        }
        drop(pyr);

        // The cell → block links.
        let mut label = vec![0u32; w * h];
        for (b, blk) in blocks.iter().enumerate() {
            for y in blk.y as usize..(blk.y + blk.h) as usize {
                label[y * w + blk.x as usize..y * w + (blk.x + blk.w) as usize].fill(b as u32);
            }
        }

        // Block adjacency: each block's right and top edges, one entry per
        // run of one neighbour (a neighbour is a rectangle: one run).
        let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(blocks.len() * 3);
        for (b, blk) in blocks.iter().enumerate() {
            let (x, y, bw, bh) = (blk.x as usize, blk.y as usize, blk.w as usize, blk.h as usize);
            if x + bw < w {
                let mut last = u32::MAX;
                for yy in y..y + bh {
                    let n = label[yy * w + x + bw];
                    if n != last {
                        pairs.push((b as u32, n));
                        last = n;
                    }
                }
            }
            if y + bh < h {
                let row = (y + bh) * w;
                let mut last = u32::MAX;
                for xx in x..x + bw {
                    let n = label[row + xx];
                    if n != last {
                        pairs.push((b as u32, n));
                        last = n;
                    }
                }
            }
        }

        // 3. Merging: links between orphans of one class and similar
        // occupancy, larger blocks first.
        // Order: the smaller block's area (decreasing), then the two blocks
        // (increasing); sorted as one integer when each fits in 21 bits.
        let area = |b: u32| (blocks[b as usize].w * blocks[b as usize].h) as u64;
        let mut links: Vec<(u64, u32, u32)> = pairs
            .iter()
            .filter(|&&(a, b)| blocks[a as usize].class == blocks[b as usize].class)
            .map(|&(a, b)| (area(a).min(area(b)), a, b))
            .collect();
        if blocks.len() < 1 << 21 && w * h < 1 << 21 {
            let mut packed: Vec<u64> = links
                .iter()
                .map(|&(ar, a, b)| (((1u64 << 21) - 1 - ar) << 42) | ((a as u64) << 21) | b as u64)
                .collect();
            packed.sort_unstable();
            let mask = (1u64 << 21) - 1;
            links = packed.iter().map(|&k| (0, ((k >> 21) & mask) as u32, (k & mask) as u32)).collect();
        } else {
            links.sort_unstable_by(|p, q| q.0.cmp(&p.0).then(p.1.cmp(&q.1)).then(p.2.cmp(&q.2)));
        }
        let nb = blocks.len();
        let mut parent: Vec<u32> = (0..nb as u32).collect();
        let mut sum: Vec<f64> = blocks.iter().map(|b| b.mean * (b.w * b.h) as f64).collect();
        let mut count: Vec<f64> = blocks.iter().map(|b| (b.w * b.h) as f64).collect();
        let mut bbox: Vec<CellBox> = blocks
            .iter()
            .map(|b| CellBox {
                x0: b.x as usize,
                y0: b.y as usize,
                x1: (b.x + b.w) as usize - 1,
                y1: (b.y + b.h) as usize - 1,
            })
            .collect();
        for &(_, a, b) in &links {
            let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
            if ra == rb {
                continue;
            }
            let (ra, rb) = (ra as usize, rb as usize);
            let (ma, mb) = (sum[ra] / count[ra], sum[rb] / count[rb]);
            if (ma - mb).abs() > params.merge {
                continue;
            }
            let joined = bbox[ra].union(&bbox[rb]);
            if params.max_extent > 0
                && (joined.x1 - joined.x0 + 1 > params.max_extent || joined.y1 - joined.y0 + 1 > params.max_extent)
            {
                continue;
            }
            let (keep, gone) = if ra < rb { (ra, rb) } else { (rb, ra) };
            parent[gone] = keep as u32;
            sum[keep] += sum[gone];
            count[keep] += count[gone];
            bbox[keep] = joined;
        }

        // 4. Regions, numbered in the order of their first block.
        let mut root_region = vec![u32::MAX; nb];
        let mut regions: Vec<Region> = Vec::new();
        for (b, block) in blocks.iter_mut().enumerate() {
            let r = find(&mut parent, b as u32) as usize;
            if root_region[r] == u32::MAX {
                root_region[r] = regions.len() as u32;
                regions.push(Region {
                    id: regions.len(),
                    class: block.class,
                    size: 0,
                    bbox: bbox[r],
                    centroid: v2(0.0, 0.0),
                    mean_occupancy: 0.0,
                    blocks: Vec::new(),
                });
            }
            let id = root_region[r] as usize;
            block.region = id;
            regions[id].blocks.push(b);
        }
        let block_region: Vec<u32> = blocks.iter().map(|b| b.region as u32).collect();
        let mut cell_region = label;
        for c in cell_region.iter_mut() {
            *c = block_region[*c as usize];
        }
        // Region → cells, grouped by a counting sort.
        let nr = regions.len();
        let mut cell_start = vec![0usize; nr + 1];
        for &r in &cell_region {
            cell_start[r as usize + 1] += 1;
        }
        for r in 0..nr {
            cell_start[r + 1] += cell_start[r];
        }
        let mut fill = cell_start.clone();
        let mut region_cells = vec![0u32; w * h];
        let mut cx = vec![0.0f64; nr];
        let mut cy = vec![0.0f64; nr];
        for (i, &r) in cell_region.iter().enumerate() {
            let r = r as usize;
            region_cells[fill[r]] = i as u32;
            fill[r] += 1;
            cx[r] += (i % w) as f64;
            cy[r] += (i / w) as f64;
        }
        let (o, cs) = (grid.origin(), grid.cell_size());
        for r in regions.iter_mut() {
            let n = cell_start[r.id + 1] - cell_start[r.id];
            r.size = n;
            let root = find(&mut parent, r.blocks[0] as u32) as usize;
            r.mean_occupancy = sum[root] / count[root];
            r.centroid = v2(o.x + (cx[r.id] / n as f64 + 0.5) * cs, o.y + (cy[r.id] / n as f64 + 0.5) * cs);
        }
        // Region adjacency from the block adjacency.
        let mut adjacency = vec![Vec::new(); nr];
        for &(a, b) in &pairs {
            let (ra, rb) = (block_region[a as usize] as usize, block_region[b as usize] as usize);
            if ra != rb {
                adjacency[ra].push(rb);
                adjacency[rb].push(ra);
            }
        }
        for n in adjacency.iter_mut() {
            n.sort_unstable();
            n.dedup();
        }
        Pyramid { width: w, height: h, levels, blocks, regions, cell_region, region_cells, cell_start, adjacency }
    }

    /// Columns of the grid it was built from.
    pub fn width(&self) -> usize {
        self.width
    }
    /// Rows of the grid it was built from.
    pub fn height(&self) -> usize {
        self.height
    }
    /// Number of levels of the pyramid (level 0: the cells).
    pub fn levels(&self) -> usize {
        self.levels
    }
    /// The orphan blocks (the pruned pyramid's leaves), top-down order.
    pub fn blocks(&self) -> &[Block] {
        &self.blocks
    }
    /// The regions, by id.
    pub fn regions(&self) -> &[Region] {
        &self.regions
    }
    /// The region of id `r`.
    pub fn region(&self, r: usize) -> &Region {
        &self.regions[r]
    }
    /// The region of cell `(x, y)`.
    pub fn region_of(&self, x: usize, y: usize) -> usize {
        self.cell_region[y * self.width + x] as usize
    }
    /// The region of the cell at index `i` of the grid.
    pub fn region_of_index(&self, i: usize) -> usize {
        self.cell_region[i] as usize
    }
    /// The region of the cell containing point `p` of `grid` (the grid the
    /// pyramid was built from), if inside.
    pub fn region_at(&self, grid: &OccupancyGrid, p: Vec2) -> Option<usize> {
        grid.cell_of(p).map(|(x, y)| self.region_of(x, y))
    }
    /// The region of every cell, by cell index.
    pub fn cell_regions(&self) -> &[u32] {
        &self.cell_region
    }
    /// The cell indices of region `r`, increasing.
    pub fn cells(&self, r: usize) -> &[u32] {
        &self.region_cells[self.cell_start[r]..self.cell_start[r + 1]]
    }
    /// The regions adjacent to region `r` (sharing an edge of cells), increasing.
    pub fn neighbours(&self, r: usize) -> &[usize] {
        &self.adjacency[r]
    }
    /// Whether regions `a` and `b` are adjacent.
    pub fn adjacent(&self, a: usize, b: usize) -> bool {
        self.adjacency[a].binary_search(&b).is_ok()
    }
}
