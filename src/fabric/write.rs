//! Text a designer reads: the fabric file `rosette fabric import` writes, with every
//! value's source, and the sheet template `rosette fabric template` prints.

use super::derived::Import;
use super::sheet::{SheetKind, Sheets, TEXT_FIELDS, Use};

/// Units of the fabric keys, for the comments beside them.
fn key_unit(key: &str) -> &'static str {
    match key {
        "areal_density" => "kg/m²",
        "thickness" => "m",
        "shear_modulus" => "N/m",
        "bending_warp" | "bending_weft" | "bending_bias" => "N·m",
        "tensile_warp" | "tensile_weft" => "[[strain, N/m], ...]",
        "bending_curve" => "[[1/m, N·m/m], ...]",
        _ => "",
    }
}

/// A number as TOML writes it back to the same f64: plain where that reads easily,
/// otherwise in exponent form.
pub fn number(v: f64) -> String {
    // Ten significant figures: a unit factor's last-bit rounding (16.8 mg/cm² × 0.01 =
    // 0.16799999999999998 kg/m²) is not worth a reader's attention.
    let v: f64 = format!("{v:.9e}").parse().expect("a formatted float parses");
    let plain = format!("{v}");
    if v == 0.0 || (1e-3..1e6).contains(&v.abs()) {
        if plain.contains('.') || plain.contains('e') { plain } else { format!("{plain}.0") }
    } else {
        format!("{v:e}")
    }
}

fn value(v: &toml::Value) -> String {
    match v {
        toml::Value::Float(f) => number(*f),
        toml::Value::Array(items) => format!("[{}]", items.iter().map(value).collect::<Vec<_>>().join(", ")),
        other => other.to_string(),
    }
}

/// The fabric file for `import`: `table` is the converted fabric (sheets expanded), each
/// key written under a comment with its source (from `import`, or "given directly"), then
/// the sheet itself as comments. `origin` names the sheet file.
pub fn fabric_file(table: &toml::Table, sheets: &Sheets, import: &Import, origin: &str) -> String {
    let text = |key: &str| table.get(key).and_then(toml::Value::as_str).unwrap_or_default().to_string();
    let (name, description) = (text("name"), text("description"));
    let mut out = String::new();
    out += &format!("# {}\n", if name.is_empty() { "Imported fabric" } else { &name });
    out += &format!("# Written by `rosette fabric import {origin}`. Each key's source is the comment above it;\n");
    out += "# units are SI per unit width, converted with the exact factors of docs/fabric-sheets.md.\n";
    for section in sheets.sections() {
        if let Some(source) = section.source() {
            out += &format!("# {} sheet: {source}\n", section.kind.title());
        }
    }
    if let Some(a) = &sheets.arcsim {
        let source = a.text.get("source").cloned().unwrap_or_else(|| a.origin());
        out += &format!("# ARCSim material: {source}\n# The projection onto Rosette's keys and what it leaves out: docs/fabric-sheets.md, ARCSim materials.\n");
    }
    out += "\n";
    out += &format!("name = {}\n", toml::Value::String(name));
    out += &format!("description = {}\n", toml::Value::String(description));
    let order = [
        "areal_density",
        "thickness",
        "tensile_warp",
        "tensile_weft",
        "shear_modulus",
        "poisson_warp",
        "bending_warp",
        "bending_weft",
        "bending_bias",
        "bending_curve",
    ];
    let others = table.keys().filter(|k| !order.contains(&k.as_str()) && !matches!(k.as_str(), "name" | "description" | "preset" | "appearance"));
    for key in order.iter().map(|k| k.to_string()).chain(others.cloned()) {
        let Some(v) = table.get(&key) else { continue };
        let source = match import.get(&key) {
            Some(d) if &d.value == v => format!("{}{}", if d.default { "DEFAULT, not measured: " } else { "" }, d.source),
            _ => format!("given directly in {origin}"),
        };
        out += &format!("\n# {source}\n");
        let unit = key_unit(&key);
        let line = format!("{key} = {}", value(v));
        out += &if unit.is_empty() { format!("{line}\n") } else { format!("{line}    # {unit}\n") };
    }
    if let Some(look) = table.get("appearance") {
        let source = match import.get("appearance") {
            Some(d) if &d.value == look => d.source.clone(),
            _ => format!("given directly in {origin}"),
        };
        let mut holder = toml::Table::new();
        holder.insert("appearance".into(), look.clone());
        out += &format!("\n# How the fabric is drawn; {source}\n");
        out += &toml::to_string(&holder).expect("a TOML table writes back");
    }
    if let Some(a) = &sheets.arcsim {
        out += &arcsim_comments(a);
        return out;
    }
    out += "\n# The sheet this came from:\n";
    for section in sheets.sections() {
        out += &format!("#\n# [{}]\n", section.kind.section());
        for (k, v) in &section.text {
            out += &format!("# {k} = {}\n", toml::Value::String(v.clone()));
        }
        for (k, r) in &section.values {
            out += &format!("# {k} = {}\n", r.written);
        }
    }
    out
}

/// The ARCSim material a fabric came from, as comments.
fn arcsim_comments(a: &super::arcsim::ArcsimSection) -> String {
    let m = &a.file_material;
    let mut out = String::from("\n# The ARCSim material this came from:\n#\n# [arcsim]\n");
    for (k, v) in &a.text {
        out += &format!("# {k} = {}\n", toml::Value::String(v.clone()));
    }
    if let Some(path) = &a.data {
        out += &format!("# data = {}\n", toml::Value::String(path.clone()));
    }
    let row = |r: &[f64]| format!("[{}]", r.iter().map(|v| format!("{v:e}")).collect::<Vec<_>>().join(", "));
    out += &format!("# density = {}\n# stretching = [\n", m.density);
    for r in &m.stretching {
        out += &format!("#     {},\n", row(r));
    }
    out += "# ]\n# bending = [\n";
    for r in &m.bending {
        out += &format!("#     {},\n", row(r));
    }
    out += "# ]\n";
    let k = a.multipliers;
    for (name, v) in [("density_mult", k.density), ("stretching_mult", k.stretching), ("bending_mult", k.bending), ("thicken", k.thicken)] {
        if v != 1.0 {
            out += &format!("# {name} = {v}\n");
        }
    }
    out
}

/// A sheet to fill in: every field of every standard (or of one), with its unit and
/// meaning and an example value. The fields the simulator uses are live with example
/// values, so that the template imports as it stands; the rest are commented out.
pub fn template(only: Option<SheetKind>) -> String {
    let mut out = String::from(
        "# A fabric's measurement sheet for `rosette fabric import SHEET.toml`.\n\
         # Replace the example values with your measurements and delete what you did not measure:\n\
         # a missing value gets a stated default and a warning. A bare number is read in the\n\
         # unit shown; a string such as \"137 g/m²\" or \"9 µN·m\" may use another unit\n\
         # (docs/fabric-sheets.md lists them). One section is enough; several combine.\n\n\
         name = \"My fabric\"\n\
         description = \"What it is and what it is for\"\n\
         # Not measured by any of the standards; 0.15 if left out.\n\
         poisson_warp = 0.15\n",
    );
    for kind in SheetKind::ALL.into_iter().filter(|k| only.is_none_or(|o| o == *k)) {
        out += &format!("\n[{}]    # {}\n", kind.section(), kind.title());
        for (name, meaning) in TEXT_FIELDS {
            match *name {
                "source" => out += "source = \"author, year, title, table (or: measured by whom, when)\"\n",
                "standard" => out += &format!("standard = \"{}\"\n", kind.title()),
                _ => out += &format!("# {name} = \"\"    # {meaning}\n"),
            }
        }
        for field in kind.fields() {
            let names: Vec<(String, f64)> = if field.directions.is_empty() {
                vec![(field.name.to_string(), field.example)]
            } else {
                // A bias strip is typically 0.8–0.95 of the warp's bending length.
                field.directions.iter().map(|d| (format!("{}_{d}", field.name), if *d == "bias" { 0.9 * field.example } else { field.example })).collect()
            };
            // The overhang is the alternative to the bending length, and a KES Fm other
            // than 500 gf/cm is rare: both are offered commented out.
            let live = field.use_ == Use::Model && !matches!(field.name, "overhang" | "Fm" | "strip_width");
            for (name, example) in names {
                let unit = if field.unit.is_empty() { String::new() } else { format!("{}, ", field.unit) };
                let hash = if live { "" } else { "# " };
                out += &format!("{hash}{name} = {}    # {unit}{}\n", number(example), field.meaning);
            }
        }
    }
    out
}
