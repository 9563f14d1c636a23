//! Reading LBNL BSDF XML (WINDOW6 format) through roxmltree: matrices over
//! Klems angle bases, or Radiance's tensor trees (`IncidentDataStructure`
//! `TensorTree3`/`TensorTree4`, [`crate::tensor_tree`]); the elements
//! heliodon needs, matched by local name (files carry WINDOW's namespace),
//! with errors that name the file and line.

use std::path::Path;

use roxmltree::Node;

use crate::tensor_tree::TensorTree;

/// One ring of a Klems basis: its polar bounds (degrees) and φ divisions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ring {
    pub theta_low: f64,
    pub theta_high: f64,
    pub phis: usize,
}

/// A Klems angle basis.
#[derive(Debug, Clone, PartialEq)]
pub struct Basis {
    pub name: String,
    pub rings: Vec<Ring>,
}

impl Basis {
    pub fn patch_count(&self) -> usize {
        self.rings.iter().map(|r| r.phis).sum()
    }
}

/// A scattering matrix: `values[o * incoming + i]`, BSDF (1/sr) from
/// incoming patch `i` to outgoing patch `o`.
#[derive(Debug, Clone, PartialEq)]
pub struct Matrix {
    pub incoming: usize,
    pub values: Vec<f64>,
}

impl Matrix {
    pub fn get(&self, incoming: usize, outgoing: usize) -> f64 {
        self.values[outgoing * self.incoming + incoming]
    }
}

/// What heliodon uses of a BSDF file: for light from outside, its
/// transmission and reflection (visible if given, else solar).
#[derive(Debug, Clone)]
pub struct BsdfFile {
    pub scattering: Scattering,
    /// "Visible" or "Solar".
    pub wavelength: String,
}

/// The scattering data of a file, as its kind keeps it: transmission and
/// reflection of light from outside, and the reflection of light from the
/// room ("Reflection Back").
#[derive(Debug, Clone)]
pub enum Scattering {
    /// Matrices over a Klems basis.
    Klems { basis: Basis, transmission: Matrix, reflection: Option<Matrix>, back_reflection: Option<Matrix> },
    /// Tensor trees (Radiance's frame: +z into the room). `transmission`
    /// is "Transmission Front" (light from outside), or, when only the
    /// back one is given, "Transmission Back" read by reciprocity
    /// (`reciprocal`: query it with the two directions exchanged).
    TensorTree { transmission: TensorTree, reciprocal: bool, reflection: Option<TensorTree>, back_reflection: Option<TensorTree> },
}

/// Klems bases have 145 patches at most (the full basis); this leaves room
/// for finer custom bases while refusing sizes that only a broken or hostile
/// file declares (a matrix is n² values).
const MAX_BASIS_PATCHES: usize = 2_000;

/// The parsed document and its file's name, for errors.
struct Reader<'a, 'i> {
    doc: &'a roxmltree::Document<'i>,
    file: &'a Path,
    /// Lines before the XML declaration, to number lines as the file does.
    skipped_lines: u32,
}

impl<'a, 'i> Reader<'a, 'i> {
    /// `file:line` of a node.
    fn at(&self, node: Node) -> String {
        format!("{}:{}", self.file.display(), self.line(node.range().start))
    }

    /// The file's line of a byte offset in the parsed text.
    fn line(&self, offset: usize) -> u32 {
        self.doc.text_pos_at(offset).row + self.skipped_lines
    }

    fn child(parent: Node<'a, 'i>, tag: &str) -> Option<Node<'a, 'i>> {
        parent.children().find(|n| n.has_tag_name(tag))
    }

    fn required(&self, parent: Node<'a, 'i>, tag: &str) -> Result<Node<'a, 'i>, String> {
        Self::child(parent, tag).ok_or_else(|| format!("{}: missing <{tag}>", self.at(parent)))
    }

    fn content(node: Node) -> String {
        node.text().unwrap_or("").trim().to_string()
    }

    /// Every `<WavelengthDataBlock>`: its wavelength, direction and node;
    /// a scattering data type other than BTDF or BRDF is refused.
    fn blocks(&self) -> Result<Vec<(String, String, Node<'a, 'i>)>, String> {
        let mut blocks = Vec::new();
        for data in self.doc.root_element().descendants().filter(|n| n.has_tag_name("WavelengthData")) {
            let wavelength = Self::content(self.required(data, "Wavelength")?);
            for block in data.children().filter(|n| n.has_tag_name("WavelengthDataBlock")) {
                let direction = Self::content(self.required(block, "WavelengthDataDirection")?);
                if let Some(kind) = Self::child(block, "ScatteringDataType")
                    && !Self::content(kind).eq_ignore_ascii_case("BTDF")
                    && !Self::content(kind).eq_ignore_ascii_case("BRDF")
                {
                    return Err(format!("{}: scattering data type '{}' is not supported", self.at(kind), Self::content(kind)));
                }
                blocks.push((wavelength.clone(), direction, block));
            }
        }
        Ok(blocks)
    }

    /// A block's `<ScatteringData>`, its text and the text's byte offset
    /// (to place a bad value on its own line).
    fn scattering_text(&self, block: Node<'a, 'i>) -> Result<(Node<'a, 'i>, &'a str, usize), String> {
        let data = self.required(block, "ScatteringData")?;
        let (text, start) = data.first_child().map_or(("", data.range().start), |t| (t.text().unwrap_or(""), t.range().start));
        Ok((data, text, start))
    }

    fn number(&self, node: Node, what: &str) -> Result<f64, String> {
        let value = Self::content(node);
        value
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("{}: {what} '{value}' is not a finite number", self.at(node)))
    }
}

/// Reads a BSDF XML file's text (parsed by roxmltree; every error names
/// the file and line).
pub fn parse(text: &str, file: &Path) -> Result<BsdfFile, String> {
    // genBSDF leaves a "Recover using: ..." line before the XML declaration
    // in the files it writes; Radiance reads them, so heliodon does too.
    let start = text.find('<').unwrap_or(0);
    let (skipped_lines, text) = (text[..start].matches('\n').count() as u32, &text[start..]);
    let doc = roxmltree::Document::parse(text).map_err(|e| {
        let row = e.pos().row + skipped_lines;
        let truncated = matches!(e, roxmltree::Error::UnclosedRootNode | roxmltree::Error::UnexpectedEndOfStream)
            || e.pos().row as usize >= text.lines().count();
        format!("{}:{row}: not well-formed XML: {e}{}", file.display(), if truncated { " (the file looks truncated)" } else { "" })
    })?;
    let r = Reader { doc: &doc, file, skipped_lines };
    let root = doc.root_element();
    let structure = root.descendants().find(|n| n.has_tag_name("IncidentDataStructure")).map(Reader::content);
    match structure.as_deref() {
        Some("TensorTree3") => tensor_trees(&r, 3),
        Some("TensorTree4") => tensor_trees(&r, 4),
        Some(other) if !matches!(other, "Rows" | "Columns") => Err(format!(
            "{}: IncidentDataStructure '{other}' is not one heliodon reads (Columns or Rows over a Klems basis, TensorTree3 or TensorTree4)",
            file.display()
        )),
        _ => klems(&r, structure.as_deref() == Some("Rows")),
    }
}

/// The matrices of a file over a Klems basis (`rows_incident`: rows list
/// incoming directions).
fn klems(r: &Reader, rows_incident: bool) -> Result<BsdfFile, String> {
    let (root, file) = (r.doc.root_element(), r.file);
    let Some(basis_element) = root.descendants().find(|n| n.has_tag_name("AngleBasis")) else {
        return Err(format!("{}: no <AngleBasis> and no tensor tree (IncidentDataStructure TensorTree3 or TensorTree4)", file.display()));
    };
    let name = Reader::content(r.required(basis_element, "AngleBasisName")?);
    if !name.contains("Klems") {
        return Err(format!(
            "{}: angle basis '{name}' is not a Klems basis (nor is the file a tensor tree: IncidentDataStructure TensorTree3 or TensorTree4)",
            r.at(basis_element)
        ));
    }
    let mut rings = Vec::new();
    for block in basis_element.children().filter(|n| n.has_tag_name("AngleBasisBlock")) {
        let phis = r.number(r.required(block, "nPhis")?, "nPhis")?;
        let bounds = r.required(block, "ThetaBounds")?;
        let low = r.number(r.required(bounds, "LowerTheta")?, "LowerTheta")?;
        let high = r.number(r.required(bounds, "UpperTheta")?, "UpperTheta")?;
        if phis < 1.0
            || phis.fract() != 0.0
            || phis > MAX_BASIS_PATCHES as f64
            || !(0.0..=90.0).contains(&low)
            || !(low..=90.0).contains(&high)
        {
            return Err(format!("{}: bad angle basis block (nPhis {phis}, theta {low}..{high})", r.at(block)));
        }
        rings.push(Ring { theta_low: low, theta_high: high, phis: phis as usize });
    }
    if rings.is_empty() {
        return Err(format!("{}: angle basis '{name}' has no blocks", r.at(basis_element)));
    }
    let basis = Basis { name, rings };
    let n = basis.patch_count();
    if n > MAX_BASIS_PATCHES {
        return Err(format!(
            "{}: angle basis '{}' has {n} patches; at most {MAX_BASIS_PATCHES} are supported",
            r.at(basis_element),
            basis.name
        ));
    }
    // Scattering blocks by wavelength and direction.
    let mut blocks: Vec<(String, String, Matrix)> = Vec::new();
    for (wavelength, direction, block) in r.blocks()? {
        let (data, values_text, values_start) = r.scattering_text(block)?;
        let mut values = Vec::with_capacity(n * n);
        for token in values_text.split(|c: char| c.is_whitespace() || c == ',').filter(|t| !t.is_empty()) {
            match token.parse::<f64>() {
                Ok(v) if v.is_finite() => values.push(v.max(0.0)),
                _ => {
                    let offset = values_start + (token.as_ptr() as usize - values_text.as_ptr() as usize);
                    return Err(format!("{}:{}: scattering value '{token}' is not a finite number", file.display(), r.line(offset)));
                }
            }
        }
        if values.len() != n * n {
            return Err(format!(
                "{}: {direction} ({wavelength}) has {} values; basis '{}' needs {n} × {n} = {}",
                r.at(data),
                values.len(),
                basis.name,
                n * n
            ));
        }
        if rows_incident {
            // Rows list incoming directions: transpose to outgoing-major.
            let mut transposed = vec![0.0; n * n];
            for (k, v) in values.iter().enumerate() {
                transposed[(k % n) * n + k / n] = *v;
            }
            values = transposed;
        }
        blocks.push((wavelength.clone(), direction, Matrix { incoming: n, values }));
    }
    let wavelength = photometric(&blocks);
    let find = |direction: &str| blocks.iter().find(|b| b.0 == wavelength && b.1 == direction).map(|b| b.2.clone());
    let transmission = match find("Transmission Front") {
        Some(matrix) => matrix,
        // Reciprocity: front transmission from i to o is back transmission from o to i.
        None => {
            let back = find("Transmission Back").ok_or_else(|| format!("{}: no transmission data ({wavelength})", file.display()))?;
            let mut values = vec![0.0; n * n];
            for i in 0..n {
                for o in 0..n {
                    values[o * n + i] = back.get(o, i);
                }
            }
            Matrix { incoming: n, values }
        }
    };
    let scattering =
        Scattering::Klems { basis, transmission, reflection: find("Reflection Front"), back_reflection: find("Reflection Back") };
    Ok(BsdfFile { scattering, wavelength: wavelength.to_string() })
}

/// The tensor trees of a file of `dims` (3 or 4) dimensions.
fn tensor_trees(r: &Reader, dims: usize) -> Result<BsdfFile, String> {
    let mut blocks: Vec<(String, String, TensorTree)> = Vec::new();
    for (wavelength, direction, block) in r.blocks()? {
        // CIE-u and CIE-v trees colour the light; heliodon's panels are grey.
        if !matches!(wavelength.as_str(), "Visible" | "Solar") {
            continue;
        }
        let basis = r.required(block, "AngleBasis")?;
        if Reader::content(basis) != "LBNL/Shirley-Chiu" {
            return Err(format!(
                "{}: a tensor tree's angle basis must be LBNL/Shirley-Chiu, not '{}'",
                r.at(basis),
                Reader::content(basis)
            ));
        }
        let (_, text, start) = r.scattering_text(block)?;
        let tree = TensorTree::parse(text, dims).map_err(|(at, why)| format!("{}:{}: {why}", r.file.display(), r.line(start + at)))?;
        blocks.push((wavelength, direction, tree));
    }
    let wavelength = photometric(&blocks);
    let mut find = |direction: &str| {
        let found = blocks.iter().position(|b| b.0 == wavelength && b.1 == direction);
        found.map(|k| blocks.swap_remove(k).2)
    };
    let reflection = find("Reflection Front");
    let back_reflection = find("Reflection Back");
    let (transmission, reciprocal) = match (find("Transmission Front"), find("Transmission Back")) {
        (Some(front), _) => (front, false),
        (None, Some(back)) => (back, true),
        (None, None) => return Err(format!("{}: no transmission tree ({wavelength})", r.file.display())),
    };
    let scattering = Scattering::TensorTree { transmission, reciprocal, reflection, back_reflection };
    Ok(BsdfFile { scattering, wavelength: wavelength.to_string() })
}

/// "Visible" when a file has visible data, else "Solar".
fn photometric<T>(blocks: &[(String, String, T)]) -> &'static str {
    if blocks.iter().any(|b| b.0 == "Visible") { "Visible" } else { "Solar" }
}
