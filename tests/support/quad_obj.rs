//! Writing OBJ models one quad at a time, for the scenes tests and
//! benchmarks generate. Not a test target of its own: included by path
//! (`#[path = ".../tests/support/quad_obj.rs"] mod quad_obj;`).

use std::fmt::Write as _;

/// An OBJ model built quad by quad, each with its material.
pub struct QuadObj {
    text: String,
    vertices: usize,
}

impl QuadObj {
    /// An empty model whose materials come from the MTL file `mtl`.
    pub fn new(mtl: &str) -> Self {
        Self { text: format!("mtllib {mtl}\n"), vertices: 0 }
    }

    /// Adds a quad of `material`; the order of its corners gives its normal.
    pub fn quad(&mut self, material: &str, corners: [[f64; 3]; 4]) {
        let _ = writeln!(self.text, "usemtl {material}");
        for v in corners {
            let _ = writeln!(self.text, "v {} {} {}", v[0], v[1], v[2]);
        }
        let n = self.vertices;
        let _ = writeln!(self.text, "f {} {} {} {}", n + 1, n + 2, n + 3, n + 4);
        self.vertices += 4;
    }

    /// The OBJ text.
    pub fn text(&self) -> &str {
        &self.text
    }
}
