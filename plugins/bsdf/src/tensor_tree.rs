//! Radiance's variable-resolution BSDFs ("tensor trees", Radiance's
//! src/common/bsdf_t.c, written by genBSDF and bsdf2ttree with `-t3` or
//! `-t4`): the BSDF over a unit hypercube of incoming × outgoing
//! coordinates, split in halves along every axis where it varies and kept
//! as grids of leaves where it does not.
//!
//! The text of a `<ScatteringData>` block is one node: `{` then either
//! 2^d nodes (the halves, the bit i of a child's index telling which half
//! of axis i it covers) or 2^(d·k) values (a grid of k levels, the first
//! axis slowest), then `}`; values are separated by white space or commas.
//!
//! Coordinates (bsdf_t.c's SDqueryTre), with Radiance's vectors pointing
//! away from the surface, `i` toward the source and `o` the way light
//! leaves: directions on a hemisphere map to the unit square through the
//! Shirley–Chiu concentric map of their (x, y) (equal areas are equal
//! projected solid angles, π per square).
//! - 4-D (anisotropic): the square of (−i.x, −i.y), then that of (o.x, o.y).
//! - 3-D (isotropic): ½ − ½·sin θᵢ, then the square of `o` turned about z
//!   so that the light's azimuth of travel is 0.

use heliodon_core::glam::DVec3;

/// Halvings of an axis, at most: 2⁻¹⁶ is far finer than any file's leaves
/// (genBSDF goes to 2⁻⁷), and a hostile file cannot nest without end.
const MAX_DEPTH: usize = 16;

/// Values in a tree, at most: a full 4-D grid of 2⁶ per axis is 2²⁴.
const MAX_VALUES: usize = 1 << 26;

/// A parsed tensor tree of 3 or 4 dimensions.
#[derive(Debug, Clone, PartialEq)]
pub struct TensorTree {
    dims: usize,
    root: Node,
}

#[derive(Debug, Clone, PartialEq)]
enum Node {
    /// 2^d halves.
    Branch(Vec<Node>),
    /// A grid of 2^(d·log2) values, BSDF in 1/sr.
    Grid { log2: u32, values: Vec<f32> },
}

/// What went wrong in a tree's text: the byte offset it was found at and why.
pub type ParseError = (usize, String);

impl TensorTree {
    /// Parses the text of a `<ScatteringData>` block as a tree of `dims` (3
    /// or 4) dimensions. Negative values read as 0, as Radiance reads them.
    pub fn parse(text: &str, dims: usize) -> Result<Self, ParseError> {
        assert!(dims == 3 || dims == 4, "tensor trees have 3 or 4 dimensions");
        let mut tokens = Tokens { text, at: 0, values: 0 };
        let root = tokens.node(dims, 0)?;
        match tokens.next() {
            None => Ok(Self { dims, root }),
            Some((at, token)) => Err((at, format!("'{token}' after the tree's closing '}}'"))),
        }
    }

    /// 3 (isotropic) or 4 (anisotropic).
    pub fn dims(&self) -> usize {
        self.dims
    }

    /// The width of the smallest leaf along an axis of the unit hypercube.
    pub fn smallest_leaf(&self) -> f64 {
        fn smallest(node: &Node) -> f64 {
            match node {
                Node::Branch(children) => 0.5 * children.iter().map(smallest).fold(1.0, f64::min),
                Node::Grid { log2, .. } => 1.0 / f64::from(1u32 << log2),
            }
        }
        smallest(&self.root)
    }

    /// The BSDF (1/sr) for light from the source direction `toward_source`
    /// leaving along `outgoing` (unit vectors away from the surface, in the
    /// file's frame); the leaf holding them, without interpolation, as
    /// Radiance looks it up.
    pub fn value(&self, toward_source: DVec3, outgoing: DVec3) -> f64 {
        let mut position = [0.0; 4];
        if self.dims == 4 {
            [position[0], position[1]] = disk_to_square(-toward_source.x, -toward_source.y);
            [position[2], position[3]] = disk_to_square(outgoing.x, outgoing.y);
        } else {
            // Turned so that the light travels along azimuth 0.
            let (sin, cos) = (-toward_source.y).atan2(-toward_source.x).sin_cos();
            let turned = (outgoing.x * cos + outgoing.y * sin, outgoing.y * cos - outgoing.x * sin);
            // Just under ½ at the normal: the axis's upper half is unused.
            position[0] = (0.5 - 1e-9) - 0.5 * toward_source.x.hypot(toward_source.y);
            [position[1], position[2]] = disk_to_square(turned.0, turned.1);
        }
        self.lookup(&position[..self.dims])
    }

    /// The leaf at `position` in the unit hypercube.
    fn lookup(&self, position: &[f64]) -> f64 {
        let mut p = [0.0; 4];
        for (p, &x) in p.iter_mut().zip(position) {
            *p = x.clamp(0.0, 1.0 - 1e-12);
        }
        let mut node = &self.root;
        loop {
            match node {
                Node::Branch(children) => {
                    let mut child = 0;
                    for (axis, p) in p[..self.dims].iter_mut().enumerate() {
                        *p *= 2.0;
                        if *p >= 1.0 {
                            *p -= 1.0;
                            child |= 1 << axis;
                        }
                    }
                    node = &children[child];
                }
                Node::Grid { log2, values } => {
                    let cells = 1usize << log2;
                    let index = p[..self.dims].iter().fold(0, |index, &x| (index << log2) + ((x * cells as f64) as usize).min(cells - 1));
                    return f64::from(values[index]);
                }
            }
        }
    }
}

/// A tree's text, token by token: `{`, `}` and numbers.
struct Tokens<'t> {
    text: &'t str,
    at: usize,
    /// Values read so far.
    values: usize,
}

impl<'t> Tokens<'t> {
    /// The next token and its offset, `None` at the end.
    fn next(&mut self) -> Option<(usize, &'t str)> {
        let rest = &self.text[self.at..];
        let start = self.at + rest.find(|c: char| !c.is_whitespace() && c != ',')?;
        let token_len = match self.text[start..].chars().next() {
            Some('{' | '}') => 1,
            _ => self.text[start..].find(|c: char| c.is_whitespace() || matches!(c, ',' | '{' | '}')).unwrap_or(self.text.len() - start),
        };
        self.at = start + token_len;
        Some((start, &self.text[start..self.at]))
    }

    fn peek(&mut self) -> Option<(usize, &'t str)> {
        let at = self.at;
        let token = self.next();
        self.at = at;
        token
    }

    fn expect(&mut self, wanted: &str, what: &str) -> Result<(), ParseError> {
        match self.next() {
            Some((_, token)) if token == wanted => Ok(()),
            Some((at, token)) => Err((at, format!("'{token}' where {what} should be"))),
            None => Err((self.text.len(), format!("the tree ends where {what} should be (truncated?)"))),
        }
    }

    fn node(&mut self, dims: usize, depth: usize) -> Result<Node, ParseError> {
        self.expect("{", "a node's '{'")?;
        let node = if self.peek().is_some_and(|(_, t)| t == "{") {
            if depth >= MAX_DEPTH {
                return Err((self.at, format!("the tree nests deeper than {MAX_DEPTH} levels")));
            }
            Node::Branch((0..1 << dims).map(|_| self.node(dims, depth + 1)).collect::<Result<_, _>>()?)
        } else {
            let start = self.at;
            let mut values = Vec::new();
            while let Some((at, token)) = self.peek().filter(|(_, t)| *t != "}" && *t != "{") {
                self.next();
                let value: f32 = token
                    .parse()
                    .ok()
                    .filter(|v: &f32| v.is_finite())
                    .ok_or_else(|| (at, format!("tensor tree value '{token}' is not a finite number")))?;
                values.push(value.max(0.0));
                self.values += 1;
                if self.values > MAX_VALUES {
                    return Err((at, format!("the tree holds more than {MAX_VALUES} values")));
                }
            }
            let n = values.len();
            let log2 = (0..=MAX_DEPTH as u32).find(|&k| dims as u32 * k < usize::BITS && 1usize << (dims as u32 * k) == n);
            let Some(log2) = log2 else {
                return Err((
                    start,
                    format!("a leaf grid of {n} values: a {dims}-D grid holds 2^({dims}·k) (1, {}, {}, …)", 1 << dims, 1 << (2 * dims)),
                ));
            };
            Node::Grid { log2, values }
        };
        self.expect("}", "a node's '}'")?;
        Ok(node)
    }
}

/// The Shirley–Chiu concentric map of the unit disk onto the unit square
/// (equal areas stay equal; rings of the disk are squares' outlines).
pub fn disk_to_square(x: f64, y: f64) -> [f64; 2] {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    let r = x.hypot(y);
    let mut phi = y.atan2(x);
    if phi < -FRAC_PI_4 {
        phi += 2.0 * PI;
    }
    // (a, b) on [-1, 1]², by the quarter of the square φ falls in.
    let (a, b) = if phi < FRAC_PI_4 {
        (r, r * phi / FRAC_PI_4)
    } else if phi < 3.0 * FRAC_PI_4 {
        (-r * (phi - FRAC_PI_2) / FRAC_PI_4, r)
    } else if phi < 5.0 * FRAC_PI_4 {
        (-r, -r * (phi - PI) / FRAC_PI_4)
    } else {
        (r * (phi - 3.0 * FRAC_PI_2) / FRAC_PI_4, -r)
    };
    [0.5 * (a + 1.0), 0.5 * (b + 1.0)]
}

/// The direction through the middle of cell `k` (row-major, the first
/// axis slowest) of a `cells` × `cells` grid on the unit square, lifted
/// from the disk onto the hemisphere on the side of `z_sign` (±1).
pub fn cell_direction(k: usize, cells: usize, z_sign: f64) -> DVec3 {
    let middle = |i: usize| (i as f64 + 0.5) / cells as f64;
    let [x, y] = square_to_disk(middle(k / cells), middle(k % cells));
    DVec3::new(x, y, z_sign * (1.0 - x * x - y * y).max(0.0).sqrt())
}

/// The inverse of [`disk_to_square`]: a point of the unit square on the disk.
pub fn square_to_disk(u: f64, v: f64) -> [f64; 2] {
    use std::f64::consts::FRAC_PI_4;
    let (a, b) = (2.0 * u - 1.0, 2.0 * v - 1.0);
    let (r, phi) = if a > -b {
        if a > b { (a, FRAC_PI_4 * (b / a)) } else { (b, FRAC_PI_4 * (2.0 - a / b)) }
    } else if a < b {
        (-a, FRAC_PI_4 * (4.0 + b / a))
    } else if b != 0.0 {
        (-b, FRAC_PI_4 * (6.0 - a / b))
    } else {
        (0.0, 0.0)
    };
    [r * phi.cos(), r * phi.sin()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_concentric_map_goes_both_ways() {
        for k in 0..400 {
            let (u, v) = ((k % 20) as f64 / 19.5 + 0.01, (k / 20) as f64 / 19.5 + 0.01);
            let [x, y] = square_to_disk(u, v);
            assert!(x.hypot(y) <= 1.0 + 1e-12);
            let [u2, v2] = disk_to_square(x, y);
            assert!((u - u2).abs() < 1e-9 && (v - v2).abs() < 1e-9, "{u} {v} -> {x} {y} -> {u2} {v2}");
        }
        // The square's centre is the disk's; its right edge is azimuth 0.
        assert_eq!(square_to_disk(0.5, 0.5), [0.0, 0.0]);
        let [x, y] = square_to_disk(1.0, 0.5);
        assert!((x - 1.0).abs() < 1e-12 && y.abs() < 1e-12);
    }

    #[test]
    fn branches_halve_every_axis_and_grids_run_first_axis_slowest() {
        // 3-D: branch 0b101 is the upper half of axes 0 and 2.
        let mut text = String::from("{");
        for child in 0..8 {
            text.push_str(&format!("{{ {child} }}"));
        }
        text.push('}');
        let tree = TensorTree::parse(&text, 3).unwrap();
        assert_eq!(tree.lookup(&[0.7, 0.2, 0.9]), 5.0);
        assert_eq!(tree.lookup(&[0.1, 0.6, 0.1]), 2.0);
        assert_eq!(tree.smallest_leaf(), 0.5);
        // A 3-D grid of 2 per axis: index (a·2 + b)·2 + c.
        let grid = TensorTree::parse("{ 0, 1, 2, 3, 4, 5, 6, 7 }", 3).unwrap();
        assert_eq!(grid.lookup(&[0.9, 0.1, 0.9]), 5.0);
        assert_eq!(grid.lookup(&[0.1, 0.9, 0.1]), 2.0);
    }

    #[test]
    fn bad_trees_are_refused_with_where() {
        let error = |text: &str| TensorTree::parse(text, 4).unwrap_err();
        assert!(error("{ 1 2 3 }").1.contains("a leaf grid of 3 values"));
        assert_eq!(error("{ 1 x }"), (4, "tensor tree value 'x' is not a finite number".into()));
        assert!(error("{ { 1 } { 2 } }").1.contains("where a node's '{' should be"));
        assert!(error("{ 1 ").1.contains("truncated"));
        assert!(error("{ 1 } 2").1.contains("after the tree's closing"));
        let deep = "{".repeat(40);
        assert!(error(&deep).1.contains("deeper than"));
        // Negative values read as 0.
        assert_eq!(TensorTree::parse("{ -1 }", 3).unwrap().lookup(&[0.2, 0.2, 0.2]), 0.0);
    }
}
