//! An ARCSim material file read and checked: the JSON of ARCSim's `materials/` folder
//! (`density`, `stretching`, `bending`), or the same three keys in a fabric file's
//! `[arcsim]` section.
//!
//! ARCSim reads these files with jsoncpp, which accepts `//` and `/* */` comments (its own
//! `aluminium.json` and `paper.json` carry them); so does Rosette. Every value is checked
//! before anything is converted, and an error names the field by its place in the file
//! (`stretching[2][3]`) and says how to fix it.

use std::path::Path;
use thiserror::Error;

/// Rows of the stretching table: the zero-strain sample, then the strained samples with
/// the largest principal stretch at 0°, 22.5°, 45°, 67.5° and 90° from the material's u
/// axis (ARCSim's conf.cpp, `parse(StretchingSamples&, …)`).
pub const STRETCHING_ROWS: usize = 6;
/// Columns of a stretching row: c11, c12, c22, c33, N/m.
pub const STRETCHING_COLUMNS: usize = 4;
/// Rows of the bending table: hinge edges at 0°, 45° and 90° from the u axis.
pub const BENDING_ROWS: usize = 3;
/// Columns of a bending row: five curvature samples.
pub const BENDING_COLUMNS: usize = 5;

/// Mass per area an ARCSim material may have, kg/m²: Rosette's floor of 1 g/m², and
/// 10 kg/m², ten times a heavy canvas. ARCSim's own non-fabric files (aluminium foil, paper)
/// lie at 0.07 and 0.1.
pub const DENSITY_RANGE: (f64, f64) = (1e-3, 10.0);


/// The three tables of an ARCSim material, in ARCSim's units.
#[derive(Debug, Clone, PartialEq)]
pub struct ArcsimMaterial {
    /// Mass per area, kg/m² (ARCSim's cloth.hpp: `double density; // area density`).
    pub density: f64,
    /// Stretching samples [c11, c12, c22, c33], N/m: row 0 at zero strain, rows 1–5 at the
    /// strain sample with the principal stretch at 0°, 22.5°, 45°, 67.5°, 90°.
    pub stretching: [[f64; STRETCHING_COLUMNS]; STRETCHING_ROWS],
    /// Bending samples, N·m: rows for hinge edges at 0°, 45°, 90° from u, columns at
    /// curvature samples 0–4.
    pub bending: [[f64; BENDING_COLUMNS]; BENDING_ROWS],
}

/// Why an ARCSim material cannot be read. The message names the file and the field.
#[derive(Debug, Clone, Error, PartialEq)]
pub enum ArcsimError {
    #[error("cannot read {path}: {message}")]
    Io { path: String, message: String },
    /// The bounded reader's refusal, whose message names the file already.
    #[error("{message}")]
    NotAMaterial { path: String, message: String },
    #[error("{file}: not valid JSON: {message} (line {line}, column {column})")]
    Syntax { file: String, message: String, line: usize, column: usize },
    #[error("{file}: {field}: {message}")]
    Field { file: String, field: String, message: String },
}

fn field_error(file: &str, field: impl Into<String>, message: impl Into<String>) -> ArcsimError {
    ArcsimError::Field { file: file.to_string(), field: field.into(), message: message.into() }
}

/// Reads an ARCSim material file: a regular file of a material's size (`io::read`), JSON with
/// comments allowed.
pub fn read_file(path: &Path) -> Result<ArcsimMaterial, ArcsimError> {
    Ok(read_document(path)?.0)
}

/// Reads an ARCSim material file as [`read_file`] does, with the fabric's look where the
/// file carries one (an `"appearance"` object, which Rosette writes beside the three tables
/// and ARCSim's reader passes over).
pub fn read_document(path: &Path) -> Result<(ArcsimMaterial, Option<serde_json::Value>), ArcsimError> {
    let text = read_text(path)?;
    parse_document(&text, &path.display().to_string())
}

/// The text of a material file, read only if it is a regular file of a material's size
/// (the bounded reader every input file goes through, `io::read`).
pub fn read_text(path: &Path) -> Result<String, ArcsimError> {
    crate::io::read::read_text(path, crate::io::read::FileKind::Arcsim)
        .map_err(|e| ArcsimError::NotAMaterial { path: path.display().to_string(), message: e.to_string() })
}

/// Parses an ARCSim material's JSON (comments allowed); `file` names it in errors.
pub fn parse_json(text: &str, file: &str) -> Result<ArcsimMaterial, ArcsimError> {
    Ok(parse_document(text, file)?.0)
}

/// Parses an ARCSim material's JSON, and returns its `"appearance"` object beside it, if it
/// has one (not checked here: it becomes the fabric's `[appearance]`, checked with it).
pub fn parse_document(text: &str, file: &str) -> Result<(ArcsimMaterial, Option<serde_json::Value>), ArcsimError> {
    let stripped = strip_comments(text).map_err(|(line, column)| ArcsimError::Syntax {
        file: file.into(),
        message: "a /* comment */ is not closed".into(),
        line,
        column,
    })?;
    let value: serde_json::Value = serde_json::from_str(&stripped).map_err(|e| ArcsimError::Syntax {
        file: file.into(),
        message: e.to_string().split(" at line").next().unwrap_or_default().to_string(),
        line: e.line(),
        column: e.column(),
    })?;
    let object = value
        .as_object()
        .ok_or_else(|| field_error(file, "(top level)", "must be an object { \"density\": …, \"stretching\": […], \"bending\": […] }"))?;
    for key in object.keys() {
        if !["density", "stretching", "bending", "appearance"].contains(&key.as_str()) {
            return Err(field_error(
                file,
                key.as_str(),
                "not a key of an ARCSim material; its keys are density, stretching and bending (and Rosette's appearance)",
            ));
        }
    }
    let material = from_fields(file, "", object.get("density"), object.get("stretching"), object.get("bending"))?;
    Ok((material, object.get("appearance").cloned()))
}

/// Builds a material from its three fields (JSON values, from a material file or a fabric
/// file's `[arcsim]` section); `prefix` goes before field names (`arcsim.`).
pub fn from_fields(
    file: &str,
    prefix: &str,
    density: Option<&serde_json::Value>,
    stretching: Option<&serde_json::Value>,
    bending: Option<&serde_json::Value>,
) -> Result<ArcsimMaterial, ArcsimError> {
    let name = |f: &str| format!("{prefix}{f}");
    let missing = |f: &str, what: &str| field_error(file, name(f), format!("missing: an ARCSim material gives {what}"));
    let density = density.ok_or_else(|| missing("density", "its mass per area in kg/m²"))?;
    let density = number(file, &name("density"), density)?;
    let (low, high) = DENSITY_RANGE;
    if !(low..=high).contains(&density) {
        return Err(field_error(
            file,
            name("density"),
            format!(
                "{density} is outside {low}–{high} kg/m²: ARCSim's material files give the mass per area in kg/m² \
                 (0.324 for an 11 oz denim); a density in kg/m³ must be multiplied by the thickness in m"
            ),
        ));
    }
    let stretching = table::<STRETCHING_ROWS, STRETCHING_COLUMNS>(
        file,
        &name("stretching"),
        stretching.ok_or_else(|| missing("stretching", "6 rows of [c11, c12, c22, c33] in N/m"))?,
        "[c11, c12, c22, c33] in N/m: the zero-strain row, then the strained rows at 0°, 22.5°, 45°, 67.5°, 90°",
    )?;
    let bending = table::<BENDING_ROWS, BENDING_COLUMNS>(
        file,
        &name("bending"),
        bending.ok_or_else(|| missing("bending", "3 rows of 5 samples in N·m"))?,
        "5 samples in N·m: rows for hinge edges at 0°, 45°, 90°, columns at curvature samples 0 to 4",
    )?;
    // A sheet with no stiffness at rest in some direction has no stable state; ARCSim would
    // clamp the sample to zero and leave the cloth without resistance there.
    for (k, what) in [(0, "c11"), (2, "c22"), (3, "c33")] {
        if stretching[0][k] <= 0.0 {
            return Err(field_error(
                file,
                format!("{}[0][{k}]", name("stretching")),
                format!("{what} at zero strain is {}: it must be positive (the sheet's stiffness at rest)", stretching[0][k]),
            ));
        }
    }
    // The rest plate must resist a pull along each axis: C11·C22 > C12² (with C12 clamped
    // at zero as ARCSim does), or the uniaxial stiffness E = C11 − C12²/C22 is zero or less.
    let [c11, c12, c22, _] = stretching[0];
    if c12.max(0.0).powi(2) >= c11 * c22 {
        return Err(field_error(
            file,
            format!("{}[0][1]", name("stretching")),
            format!(
                "c12 = {c12} at zero strain is at least √(c11·c22) = {:.4}: the sheet would have no stiffness under a \
                 pull along u or v (c11 − c12²/c22 ≤ 0); c12 must be smaller than √(c11·c22)",
                (c11 * c22).sqrt()
            ),
        ));
    }
    for (i, row) in bending.iter().enumerate() {
        for (j, &v) in row.iter().enumerate() {
            if v <= 0.0 {
                return Err(field_error(
                    file,
                    format!("{}[{i}][{j}]", name("bending")),
                    format!("{v} N·m: bending samples must be positive (a hinge with no rigidity folds freely)"),
                ));
            }
        }
    }
    Ok(ArcsimMaterial { density, stretching, bending })
}

fn number(file: &str, field: &str, value: &serde_json::Value) -> Result<f64, ArcsimError> {
    let v = value.as_f64().ok_or_else(|| field_error(file, field, format!("{value} is not a number")))?;
    if !v.is_finite() {
        return Err(field_error(file, field, format!("{v} is not a finite number")));
    }
    Ok(v)
}

fn table<const R: usize, const C: usize>(file: &str, field: &str, value: &serde_json::Value, layout: &str) -> Result<[[f64; C]; R], ArcsimError> {
    let rows = value.as_array().ok_or_else(|| field_error(file, field, format!("must be a table of {R} rows of {layout}")))?;
    if rows.len() != R {
        return Err(field_error(file, field, format!("has {} rows; an ARCSim table has {R} rows of {layout}", rows.len())));
    }
    let mut out = [[0.0; C]; R];
    for (i, row) in rows.iter().enumerate() {
        let row_field = format!("{field}[{i}]");
        let values = row.as_array().ok_or_else(|| field_error(file, &row_field, format!("must be a row of {C} numbers ({layout})")))?;
        if values.len() != C {
            return Err(field_error(file, &row_field, format!("has {} values; each row has {C} ({layout})", values.len())));
        }
        for (j, v) in values.iter().enumerate() {
            out[i][j] = number(file, &format!("{row_field}[{j}]"), v)?;
        }
    }
    Ok(out)
}

/// Removes `//` and `/* */` comments outside strings, keeping line breaks so that JSON
/// errors point at the right line. Err((line, column)) for an unclosed block comment.
///
/// Written here rather than taken from a crate: jsoncpp's comment rule is these two forms
/// and nothing else, and the function is shorter than a dependency's manifest entry.
pub fn strip_comments(text: &str) -> Result<String, (usize, usize)> {
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars().peekable();
    let (mut in_string, mut escaped) = (false, false);
    let (mut line, mut column) = (1, 0);
    while let Some(c) = chars.next() {
        column += 1;
        if c == '\n' {
            (line, column) = (line + 1, 0);
        }
        if in_string {
            out.push(c);
            match (escaped, c) {
                (true, _) => escaped = false,
                (false, '\\') => escaped = true,
                (false, '"') => in_string = false,
                _ => {}
            }
            continue;
        }
        match (c, chars.peek()) {
            ('"', _) => {
                in_string = true;
                out.push(c);
            }
            ('/', Some('/')) => {
                for d in chars.by_ref() {
                    if d == '\n' {
                        out.push('\n');
                        (line, column) = (line + 1, 0);
                        break;
                    }
                }
            }
            ('/', Some('*')) => {
                let start = (line, column);
                chars.next();
                let mut previous = ' ';
                let mut closed = false;
                for d in chars.by_ref() {
                    column += 1;
                    if d == '\n' {
                        out.push('\n');
                        (line, column) = (line + 1, 0);
                    }
                    if previous == '*' && d == '/' {
                        closed = true;
                        break;
                    }
                    previous = d;
                }
                if !closed {
                    return Err(start);
                }
                out.push(' ');
            }
            _ => out.push(c),
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const DENIM: &str = r#"{
    "density": 0.324,
    "stretching": [
        [205.352005, 10.234077, 1013.88629, 53.387184],
        [232.027634, 40.646339, 1052.84289, 64.980499],
        [224.592209, 40.384563, 1054.43444, 67.184807],
        [225.951050, 62.095657, 1059.59741, 83.992020],
        [226.039566, 40.502792, 1058.27771, 75.118423],
        [225.767487, 40.917892, 1051.55712, 71.810631]
    ],
    "bending": [
        [64.196457e-6, 60.286175e-6, 60.943428e-6, 62.433697e-6, 19.824701e-6],
        [73.384567e-6, 59.671982e-6, 61.080757e-6, 68.242569e-6, 36.033474e-6],
        [96.951576e-6, 107.848228e-6, 113.060738e-6, 120.569740e-6, 79.781021e-6]
    ]
}"#;

    #[test]
    fn reads_a_material_and_its_comments() {
        let m = parse_json(DENIM, "denim.json").unwrap();
        assert_eq!(m.density, 0.324);
        assert_eq!(m.stretching[3][1], 62.095657);
        assert_eq!(m.bending[2][4], 79.781021e-6);
        let commented = format!("// thickness: h = 25.4e-6 m\n/* a block\n comment */{}", DENIM.replace("\"bending\"", "// \"x\": 1\n\"bending\""));
        assert_eq!(parse_json(&commented, "c.json").unwrap(), m);
        assert_eq!(strip_comments(r#"{"a//b": "/*"}"#).unwrap(), r#"{"a//b": "/*"}"#, "comments are not looked for inside strings");
    }

    #[test]
    fn bad_files_name_the_field() {
        let err = |text: &str| parse_json(text, "m.json").unwrap_err().to_string();
        let e = err(&DENIM.replace("[225.767487, 40.917892, 1051.55712, 71.810631]", "[225.767487, 40.917892, 1051.55712]"));
        assert!(e.contains("m.json: stretching[5]") && e.contains("has 3 values"), "{e}");
        let e = err(&DENIM.replace("0.324", "324"));
        assert!(e.contains("density") && e.contains("kg/m²"), "{e}");
        let e = err(&DENIM.replace("96.951576e-6", "-96.951576e-6"));
        assert!(e.contains("bending[2][0]") && e.contains("positive"), "{e}");
        let e = err(&DENIM.replace("205.352005", "\"x\""));
        assert!(e.contains("stretching[0][0]") && e.contains("not a number"), "{e}");
        let e = err(&DENIM.replace("205.352005", "1e999"));
        assert!(e.contains("not valid JSON"), "{e}");
        let e = err(&DENIM.replace("\"density\"", "\"densty\""));
        assert!(e.contains("densty"), "{e}");
        let e = err(&DENIM.replace(",\n        [73.384567e-6, 59.671982e-6, 61.080757e-6, 68.242569e-6, 36.033474e-6]", ""));
        assert!(e.contains("bending") && e.contains("has 2 rows"), "{e}");
        let e = err(&DENIM.replace("205.352005", "-205.352005"));
        assert!(e.contains("stretching[0][0]") && e.contains("positive"), "{e}");
        // c12 above √(c11·c22) = 456.3: no stiffness under a uniaxial pull at rest.
        let e = err(&DENIM.replace("10.234077", "500.0"));
        assert!(e.contains("stretching[0][1]") && e.contains("√(c11·c22)"), "{e}");
        let e = err("/* open");
        assert!(e.contains("not closed") && e.contains("line 1"), "{e}");
        let e = err("[1, 2]");
        assert!(e.contains("must be an object"), "{e}");
    }
}
