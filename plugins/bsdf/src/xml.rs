//! Reading LBNL BSDF XML (WINDOW6 format) with Klems angle bases: just the
//! elements heliodon needs, with errors that name the file and line.

use std::path::Path;

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
    pub fn len(&self) -> usize {
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

/// What heliodon uses of a BSDF file: the basis and, for light from
/// outside, transmission and reflection (visible if given, else solar).
#[derive(Debug, Clone)]
pub struct BsdfFile {
    pub basis: Basis,
    pub transmission: Matrix,
    pub reflection: Option<Matrix>,
    /// "Visible" or "Solar".
    pub wavelength: String,
}

/// Line number (from 1) of a byte offset.
fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].bytes().filter(|&b| b == b'\n').count() + 1
}

/// The elements named `tag` within `text[range]`: (start offset of the
/// content, the content). A missing closing tag is an error (truncated file).
fn elements<'a>(text: &'a str, range: (usize, usize), tag: &str, file: &Path) -> Result<Vec<(usize, &'a str)>, String> {
    let (mut at, end) = range;
    let open = format!("<{tag}");
    let close = format!("</{tag}>");
    let mut out = Vec::new();
    while let Some(found) = text[at..end].find(&open) {
        let start = at + found;
        let after = start + open.len();
        // `<Tag>` or `<Tag attr="...">`, not `<TagOther>`.
        match text[after..end].chars().next() {
            Some('>') | Some(' ') | Some('\t') | Some('\n') | Some('\r') | Some('/') => {}
            _ => {
                at = after;
                continue;
            }
        }
        let Some(gt) = text[after..end].find('>') else {
            return Err(format!("{}:{}: <{tag}> is cut off (the file looks truncated)", file.display(), line_of(text, start)));
        };
        let content_start = after + gt + 1;
        if text[after..after + gt].ends_with('/') {
            out.push((content_start, ""));
            at = content_start;
            continue;
        }
        let Some(stop) = text[content_start..end].find(&close) else {
            return Err(format!("{}:{}: <{tag}> has no </{tag}> (the file looks truncated)", file.display(), line_of(text, start)));
        };
        out.push((content_start, &text[content_start..content_start + stop]));
        at = content_start + stop + close.len();
    }
    Ok(out)
}

fn child<'a>(text: &'a str, parent: (usize, &'a str), tag: &str, file: &Path) -> Result<Option<(usize, &'a str)>, String> {
    Ok(elements(text, (parent.0, parent.0 + parent.1.len()), tag, file)?.into_iter().next())
}

fn required<'a>(text: &'a str, parent: (usize, &'a str), tag: &str, file: &Path) -> Result<(usize, &'a str), String> {
    child(text, parent, tag, file)?.ok_or_else(|| format!("{}:{}: missing <{tag}>", file.display(), line_of(text, parent.0)))
}

fn number(text: &str, (at, content): (usize, &str), what: &str, file: &Path) -> Result<f64, String> {
    content
        .trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| format!("{}:{}: {what} '{}' is not a finite number", file.display(), line_of(text, at), content.trim()))
}

/// Reads a BSDF XML file's text.
pub fn parse(text: &str, file: &Path) -> Result<BsdfFile, String> {
    let whole = (0, text.len());
    if !text.contains("</WindowElement>") {
        return Err(format!("{}: no </WindowElement> at the end (the file looks truncated)", file.display()));
    }
    // The angle basis (tensor trees have none, or a non-Klems one).
    let bases = elements(text, whole, "AngleBasis", file)?;
    let Some(&basis_element) = bases.first() else {
        return Err(format!("{}: no <AngleBasis>: tensor-tree BSDFs are not supported yet (use a Klems basis)", file.display()));
    };
    let name = required(text, basis_element, "AngleBasisName", file)?.1.trim().to_string();
    if !name.contains("Klems") {
        return Err(format!("{}:{}: angle basis '{name}' is not a Klems basis (tensor trees are not supported yet)", file.display(), line_of(text, basis_element.0)));
    }
    let mut rings = Vec::new();
    for block in elements(text, (basis_element.0, basis_element.0 + basis_element.1.len()), "AngleBasisBlock", file)? {
        let phis = number(text, required(text, block, "nPhis", file)?, "nPhis", file)?;
        let bounds = required(text, block, "ThetaBounds", file)?;
        let low = number(text, required(text, bounds, "LowerTheta", file)?, "LowerTheta", file)?;
        let high = number(text, required(text, bounds, "UpperTheta", file)?, "UpperTheta", file)?;
        if phis < 1.0 || phis.fract() != 0.0 || !(0.0..=90.0).contains(&low) || !(low..=90.0).contains(&high) {
            return Err(format!("{}:{}: bad angle basis block (nPhis {phis}, theta {low}..{high})", file.display(), line_of(text, block.0)));
        }
        rings.push(Ring { theta_low: low, theta_high: high, phis: phis as usize });
    }
    if rings.is_empty() {
        return Err(format!("{}:{}: angle basis '{name}' has no blocks", file.display(), line_of(text, basis_element.0)));
    }
    let basis = Basis { name, rings };
    let n = basis.len();
    let rows_incident = elements(text, whole, "IncidentDataStructure", file)?.first().is_some_and(|e| e.1.trim() == "Rows");
    // Scattering blocks by wavelength and direction.
    let mut blocks: Vec<(String, String, Matrix)> = Vec::new();
    for data in elements(text, whole, "WavelengthData", file)? {
        let wavelength = required(text, data, "Wavelength", file)?.1.trim().to_string();
        for block in elements(text, (data.0, data.0 + data.1.len()), "WavelengthDataBlock", file)? {
            let direction = required(text, block, "WavelengthDataDirection", file)?.1.trim().to_string();
            if let Some(kind) = child(text, block, "ScatteringDataType", file)?
                && !kind.1.trim().eq_ignore_ascii_case("BTDF")
                && !kind.1.trim().eq_ignore_ascii_case("BRDF")
            {
                return Err(format!("{}:{}: scattering data type '{}' is not supported", file.display(), line_of(text, kind.0), kind.1.trim()));
            }
            let data = required(text, block, "ScatteringData", file)?;
            let mut values = Vec::with_capacity(n * n);
            for token in data.1.split(|c: char| c.is_whitespace() || c == ',').filter(|t| !t.is_empty()) {
                match token.parse::<f64>() {
                    Ok(v) if v.is_finite() => values.push(v.max(0.0)),
                    _ => {
                        let offset = data.0 + data.1.find(token).unwrap_or(0);
                        return Err(format!("{}:{}: scattering value '{token}' is not a finite number", file.display(), line_of(text, offset)));
                    }
                }
            }
            if values.len() != n * n {
                return Err(format!(
                    "{}:{}: {direction} ({wavelength}) has {} values; basis '{}' needs {n} × {n} = {}",
                    file.display(),
                    line_of(text, data.0),
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
    }
    let wavelength = if blocks.iter().any(|b| b.0 == "Visible") { "Visible" } else { "Solar" };
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
    Ok(BsdfFile { basis, transmission, reflection: find("Reflection Front"), wavelength: wavelength.to_string() })
}
