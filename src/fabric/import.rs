//! From sheets to fabric keys: which section gives which key, the stated defaults, and
//! the checks that catch a mistyped sheet.
//!
//! Where several sections give the same property the first in the order KES, FAST,
//! cantilever is used and the others are compared with it (a warning if they differ by
//! more than [`AGREEMENT`]). A key written directly in the fabric file wins over every
//! sheet. docs/fabric-sheets.md is the user's version of this module.

use super::derived::{
    AGREEMENT, DEFAULT_BULK_DENSITY, DEFAULT_EMT, DEFAULT_LT, DEFAULT_POISSON, DEFAULT_SHEAR, Derived, FAST_SHEAR_CONSTANT, Import, KES_FM, WT_TOLERANCE,
};
use super::bias::{BiasStrip, STANDARD_STRIP_WIDTH, plate_rigidity_for_bending_length};
use super::sheet::{Section, SheetError, SheetKind, Sheets};
use super::tensile::{fast_curve, kes_curve};
use crate::physics::{rigidity_for_bending_length, weight_per_area};
use crate::sim::PiecewiseLinear;

fn float(v: f64) -> toml::Value {
    toml::Value::Float(v)
}

fn curve_value(curve: &[[f64; 2]]) -> toml::Value {
    toml::Value::Array(curve.iter().map(|p| toml::Value::Array(vec![float(p[0]), float(p[1])])).collect())
}

fn number(v: &toml::Value) -> Option<f64> {
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

fn curve_points(v: &toml::Value) -> Option<Vec<[f64; 2]>> {
    v.as_array()?.iter().map(|p| Some([number(p.get(0)?)?, number(p.get(1)?)?])).collect()
}

fn percent(a: f64, b: f64) -> f64 {
    100.0 * (a - b).abs() / b
}

/// A tensile curve `[[strain, N/m], ...]` and the sentence saying where it came from.
type SourcedCurve = (Vec<[f64; 2]>, String);

/// One candidate value for a property: the SI value and the sentence that says where it
/// came from.
struct Candidate {
    value: f64,
    source: String,
}

struct Deriver<'a> {
    sheets: &'a Sheets,
    explicit: &'a toml::Table,
    out: Import,
}

impl Deriver<'_> {
    fn explicit(&self, key: &str) -> Option<f64> {
        self.explicit.get(key).and_then(number)
    }

    fn push(&mut self, key: &'static str, value: toml::Value, source: String, default: bool) {
        // The section whose field the source quotes first.
        let section = (!default)
            .then(|| SheetKind::ALL.into_iter().filter_map(|k| source.find(&format!("{}.", k.section())).map(|i| (i, k))).min())
            .flatten()
            .map(|(_, k)| k);
        self.out.derived.push(Derived { key, value, source, default, section });
    }

    /// Picks the first candidate and warns about the others where they disagree.
    fn choose(&mut self, what: &str, candidates: Vec<Candidate>) -> Option<Candidate> {
        let mut iter = candidates.into_iter();
        let first = iter.next()?;
        for other in iter {
            let off = percent(other.value, first.value);
            if off > 100.0 * AGREEMENT {
                self.out.warnings.push(format!(
                    "{what}: {} differs by {off:.0} % from {}; the latter is used",
                    other.source, first.source
                ));
            }
        }
        Some(first)
    }

    fn areal_density(&mut self) -> Result<f64, SheetError> {
        let candidates: Vec<Candidate> = self
            .sheets
            .sections()
            .filter_map(|s| s.si("W").map(|value| Candidate { value, source: s.quote("W") }))
            .collect();
        let chosen = self.choose("areal density", candidates);
        match (self.explicit("areal_density"), chosen) {
            (Some(v), chosen) => {
                if let Some(c) = chosen {
                    self.push("areal_density", float(c.value), c.source, false);
                }
                Ok(v)
            }
            (None, Some(c)) => {
                self.push("areal_density", float(c.value), c.source, false);
                Ok(c.value)
            }
            (None, None) => Err(SheetError::Missing {
                what: "the mass per area".into(),
                fix: "add W to the sheet: [kes] W in mg/cm², [fast] or [cantilever] W in g/m² (or \"137 g/m²\" with a unit)"
                    .into(),
            }),
        }
    }

    fn thickness(&mut self, rho: f64) {
        let candidates: Vec<Candidate> = [(&self.sheets.kes, "T"), (&self.sheets.fast, "T2")]
            .into_iter()
            .filter_map(|(s, f)| s.as_ref().and_then(|s| s.si(f).map(|value| Candidate { value, source: s.quote(f) })))
            .collect();
        if let Some(c) = self.choose("thickness", candidates) {
            self.push("thickness", float(c.value), c.source, false);
        } else if self.explicit("thickness").is_none() {
            let value = rho / DEFAULT_BULK_DENSITY;
            self.out.warnings.push(format!(
                "thickness: the sheet gives none (KES T, FAST T2); using the mass per area over {DEFAULT_BULK_DENSITY} kg/m³ = \
                 {:.2} mm, a typical woven's bulk density (it matters only in eq. 3's twist term, when no bias rigidity is measured)",
                value * 1e3
            ));
            self.push("thickness", float(value), format!("default: mass per area / {DEFAULT_BULK_DENSITY} kg/m³"), true);
        }
    }

    /// A bending length's rigidity B = W·g·c³, with the section's own W where it has one.
    fn from_length(section: &Section, length_field: &str, c: f64, rho: f64) -> Candidate {
        let (w, w_text) = match section.si("W") {
            Some(w) => (w, section.quote("W")),
            None => (rho, "the fabric's mass per area".to_string()),
        };
        Candidate {
            value: rigidity_for_bending_length(c, weight_per_area(w)),
            source: format!("{} with {w_text}: B = W·g·c³", section.quote(length_field)),
        }
    }

    /// The bending length a cantilever section gives in `dir` (c, or half the overhang).
    fn cantilever_length(section: &Section, dir: &str) -> Result<Option<(f64, String)>, SheetError> {
        let (c, overhang) = (format!("c_{dir}"), format!("overhang_{dir}"));
        match (section.si(&c), section.si(&overhang)) {
            (Some(_), Some(_)) => Err(SheetError::Duplicate {
                section: "cantilever",
                field: c,
                other: overhang,
                fix: "give the bending length c or the overhang at 41.5° (twice c), not both".into(),
            }),
            (Some(v), None) => Ok(Some((v, c))),
            (None, Some(v)) => Ok(Some((0.5 * v, overhang))),
            (None, None) => Ok(None),
        }
    }

    fn bending(&mut self, rho: f64) -> Result<[f64; 2], SheetError> {
        let mut found: [Option<Candidate>; 2] = [None, None];
        for (i, dir) in ["warp", "weft"].into_iter().enumerate() {
            let mut candidates = Vec::new();
            if let Some(kes) = &self.sheets.kes
                && let Some(v) = kes.si(&format!("B_{dir}"))
            {
                candidates.push(Candidate { value: v, source: kes.quote(&format!("B_{dir}")) });
            }
            if let Some(fast) = &self.sheets.fast {
                let (b, c) = (format!("B_{dir}"), format!("C_{dir}"));
                let from_c = fast.si(&c).map(|len| Self::from_length(fast, &c, len, rho));
                match (fast.si(&b), from_c) {
                    (Some(v), Some(from_c)) => {
                        if percent(from_c.value, v) > 100.0 * WT_TOLERANCE {
                            return Err(SheetError::Inconsistent {
                                fields: format!("{}, {}", fast.quote(&b), fast.quote(&c)),
                                message: format!(
                                    "FAST's B = W·g·C³ gives {:.3} µN·m from the bending length, {:.0} % off the B given; \
                                     check both (and W), or give only one",
                                    from_c.value * 1e6,
                                    percent(from_c.value, v)
                                ),
                            });
                        }
                        candidates.push(Candidate { value: v, source: fast.quote(&b) });
                    }
                    (Some(v), None) => candidates.push(Candidate { value: v, source: fast.quote(&b) }),
                    (None, Some(from_c)) => candidates.push(from_c),
                    (None, None) => {}
                }
            }
            if let Some(cant) = &self.sheets.cantilever
                && let Some((len, field)) = Self::cantilever_length(cant, dir)?
            {
                candidates.push(Self::from_length(cant, &field, len, rho));
            }
            found[i] = self.choose(&format!("bending rigidity ({dir})"), candidates);
        }
        let keys = ["bending_warp", "bending_weft"];
        let mut values = [0.0; 2];
        for i in 0..2 {
            let explicit = self.explicit(keys[i]);
            match (&found[i], &found[1 - i], explicit) {
                (Some(c), _, e) => {
                    values[i] = e.unwrap_or(c.value);
                    self.push(keys[i], float(c.value), c.source.clone(), false);
                }
                (None, _, Some(e)) => values[i] = e,
                (None, Some(other), None) => {
                    self.out.warnings.push(format!(
                        "{}: the sheet gives only the other direction; using it for both ({})",
                        keys[i], other.source
                    ));
                    values[i] = other.value;
                    self.push(keys[i], float(other.value), format!("default: the other direction's {}", other.source), true);
                }
                (None, None, None) => {
                    return Err(SheetError::Missing {
                        what: "the bending rigidity".into(),
                        fix: "add B_warp and B_weft to [kes] (gf·cm²/cm) or [fast] (µN·m), C_warp and C_weft to [fast] or \
                              c_warp and c_weft to [cantilever] (mm)"
                            .into(),
                    });
                }
            }
        }
        Ok(values)
    }

    fn shear(&mut self) -> f64 {
        let mut candidates = Vec::new();
        if let Some(kes) = &self.sheets.kes {
            match (kes.si("G_warp"), kes.si("G_weft")) {
                (Some(a), Some(b)) if a == b => candidates.push(Candidate { value: a, source: kes.quote("G_warp") }),
                (Some(a), Some(b)) => candidates.push(Candidate {
                    value: 0.5 * (a + b),
                    source: format!("the mean of {} and {}", kes.quote("G_warp"), kes.quote("G_weft")),
                }),
                (Some(v), None) => candidates.push(Candidate { value: v, source: kes.quote("G_warp") }),
                (None, Some(v)) => candidates.push(Candidate { value: v, source: kes.quote("G_weft") }),
                (None, None) => {}
            }
        }
        if let Some(fast) = &self.sheets.fast {
            let from_eb5 = fast.si("EB5").map(|eb5| Candidate {
                value: FAST_SHEAR_CONSTANT / (100.0 * eb5),
                source: format!("{}: G = 123/EB5 N/m", fast.quote("EB5")),
            });
            match (fast.si("G"), from_eb5) {
                (Some(g), Some(e)) => {
                    if percent(e.value, g) > 3.0 {
                        self.out.warnings.push(format!("{} is not 123/EB5 = {:.2} N/m ({}); G is used", fast.quote("G"), e.value, e.source));
                    }
                    candidates.push(Candidate { value: g, source: fast.quote("G") });
                }
                (Some(g), None) => candidates.push(Candidate { value: g, source: fast.quote("G") }),
                (None, Some(e)) => candidates.push(e),
                (None, None) => {}
            }
        }
        match (self.choose("shear rigidity", candidates), self.explicit("shear_modulus")) {
            (Some(c), e) => {
                self.push("shear_modulus", float(c.value), c.source, false);
                e.unwrap_or(c.value)
            }
            (None, Some(e)) => e,
            (None, None) => {
                self.out.warnings.push(format!(
                    "shear_modulus: the sheet gives no shear rigidity (KES G, FAST G or EB5); using {DEFAULT_SHEAR} N/m, \
                     mid-range for light wovens (docs/fabric-sheets.md)"
                ));
                self.push("shear_modulus", float(DEFAULT_SHEAR), "default: docs/fabric-sheets.md".into(), true);
                DEFAULT_SHEAR
            }
        }
    }

    /// The KES curve of one direction and its source, if the sheet has tensile values for it.
    fn kes_tensile(&mut self, kes: &Section, dir: &str) -> Result<Option<SourcedCurve>, SheetError> {
        let name = |f: &str| format!("{f}_{dir}");
        let (emt, lt, wt) = (kes.si(&name("EMT")), kes.si(&name("LT")), kes.si(&name("WT")));
        let fm = kes.si("Fm").unwrap_or(KES_FM);
        let fm_text = if kes.si("Fm").is_some() { kes.quote("Fm") } else { "Fm = 500 gf/cm".into() };
        if let Some(lt) = lt
            && lt > 1.0
        {
            return Err(SheetError::Inconsistent {
                fields: kes.quote(&name("LT")),
                message: "LT above 1 would be a curve that softens as it is pulled, which KES does not report for wovens \
                          (their LT lies below 1). Check the value: LT is a ratio, not a percentage"
                    .into(),
            });
        }
        let quote3 = || format!("{}, {}, {}", kes.quote(&name("EMT")), kes.quote(&name("LT")), kes.quote(&name("WT")));
        let (emt, lt, how) = match (emt, lt, wt) {
            (Some(emt), Some(lt), Some(wt)) => {
                let expected = lt * fm * emt / 2.0;
                if percent(wt, expected) > 100.0 * WT_TOLERANCE {
                    return Err(SheetError::Inconsistent {
                        fields: quote3(),
                        message: format!(
                            "WT must equal LT·Fm·EMT/2 = {:.3} gf·cm/cm², {:.0} % off the WT given; check the three values \
                             (or give two of them and the third is computed)",
                            expected / super::units::GF_CM_PER_CM2,
                            percent(wt, expected)
                        ),
                    });
                }
                (emt, lt, quote3())
            }
            (Some(emt), Some(lt), None) => (emt, lt, format!("{}, {}", kes.quote(&name("EMT")), kes.quote(&name("LT")))),
            (Some(emt), None, Some(wt)) => {
                let lt = wt / (fm * emt / 2.0);
                if lt > 1.0 {
                    return Err(SheetError::Inconsistent {
                        fields: format!("{}, {}", kes.quote(&name("EMT")), kes.quote(&name("WT"))),
                        message: format!("together they give LT = WT/(Fm·EMT/2) = {lt:.3}, above 1 (a softening curve); check both"),
                    });
                }
                (emt, lt, format!("{}, {} (so LT = {lt:.3})", kes.quote(&name("EMT")), kes.quote(&name("WT"))))
            }
            (None, Some(lt), Some(wt)) => {
                let emt = 2.0 * wt / (lt * fm);
                (emt, lt, format!("{}, {} (so EMT = {:.2} %)", kes.quote(&name("LT")), kes.quote(&name("WT")), emt * 100.0))
            }
            (Some(emt), None, None) => {
                self.out.warnings.push(format!(
                    "tensile_{dir}: the sheet gives EMT but neither LT nor WT; using LT = {DEFAULT_LT} (docs/fabric-sheets.md)"
                ));
                (emt, DEFAULT_LT, format!("{} with the default LT = {DEFAULT_LT}", kes.quote(&name("EMT"))))
            }
            (None, Some(_), None) | (None, None, Some(_)) => {
                return Err(SheetError::Missing {
                    what: format!("kes.EMT_{dir}"),
                    fix: format!("LT or WT alone do not fix the curve's strain scale; add EMT_{dir} (%), or both LT_{dir} and WT_{dir}"),
                });
            }
            (None, None, None) => return Ok(None),
        };
        let curve = kes_curve(emt, lt, fm);
        Ok(Some((curve, format!("{how}, {fm_text}: the two-segment KES curve (docs/fabric-sheets.md)"))))
    }

    /// The FAST curve of one direction and its source, if the sheet has extensions for it.
    fn fast_tensile(&mut self, fast: &Section, dir: &str) -> Result<Option<SourcedCurve>, SheetError> {
        let names = ["E5", "E20", "E100"].map(|f| format!("{f}_{dir}"));
        let strains = [0, 1, 2].map(|i| fast.si(&names[i]));
        if strains.iter().all(Option::is_none) {
            return Ok(None);
        }
        let given: Vec<String> = names.iter().filter(|n| fast.si(n).is_some()).map(|n| fast.quote(n)).collect();
        let curve = fast_curve(strains).ok_or_else(|| SheetError::Inconsistent {
            fields: given.join(", "),
            message: "extension must grow with the load (E5 < E20 < E100); check the values and their order".into(),
        })?;
        if strains[2].is_none() {
            self.out.warnings.push(format!(
                "tensile_{dir}: no fast.E100_{dir}; above the last load given the curve goes on at its last slope"
            ));
        }
        Ok(Some((curve, format!("{}: through the FAST-3 points at 5, 20 and 100 gf/cm", given.join(", ")))))
    }

    /// Tensile curves of both directions; returns their small-strain slopes, N/m.
    fn tensile(&mut self) -> Result<[f64; 2], SheetError> {
        let mut found: [Option<SourcedCurve>; 2] = [None, None];
        for (i, dir) in ["warp", "weft"].into_iter().enumerate() {
            let kes = match self.sheets.kes.clone() {
                Some(kes) => self.kes_tensile(&kes, dir)?,
                None => None,
            };
            let fast = match self.sheets.fast.clone() {
                Some(fast) => self.fast_tensile(&fast, dir)?,
                None => None,
            };
            if let (Some(k), Some(f)) = (&kes, &fast) {
                self.out.warnings.push(format!("tensile_{dir}: both KES ({}) and FAST ({}) give a curve; KES is used", k.1, f.1));
            }
            found[i] = kes.or(fast);
        }
        let keys = ["tensile_warp", "tensile_weft"];
        let mut slopes = [0.0; 2];
        for i in 0..2 {
            let explicit = self.explicit.get(keys[i]).and_then(curve_points);
            let chosen = match (&found[i], &found[1 - i]) {
                (Some((curve, source)), _) => Some((curve.clone(), source.clone(), false)),
                (None, Some((curve, source))) if explicit.is_none() => {
                    self.out.warnings.push(format!("{}: the sheet gives only the other direction; using it for both", keys[i]));
                    Some((curve.clone(), format!("default: the other direction's {source}"), true))
                }
                (None, None) if explicit.is_none() => {
                    self.out.warnings.push(format!(
                        "{}: the sheet gives no tensile values (KES EMT/LT/WT or FAST E5/E20/E100); using a KES curve with \
                         EMT = {} % and LT = {DEFAULT_LT} (docs/fabric-sheets.md)",
                        keys[i],
                        DEFAULT_EMT * 100.0
                    ));
                    Some((kes_curve(DEFAULT_EMT, DEFAULT_LT, KES_FM), "default: docs/fabric-sheets.md".into(), true))
                }
                _ => None,
            };
            let curve = match (explicit, chosen) {
                (Some(e), chosen) => {
                    if let Some((c, source, false)) = chosen {
                        self.push(keys[i], curve_value(&c), source, false);
                    }
                    e
                }
                (None, Some((c, source, default))) => {
                    self.push(keys[i], curve_value(&c), source, default);
                    c
                }
                (None, None) => unreachable!("a missing curve is defaulted above"),
            };
            slopes[i] = PiecewiseLinear::new_material(&curve).map(|c| c.initial_slope()).unwrap_or(f64::NAN);
        }
        Ok(slopes)
    }

    fn poisson(&mut self) -> f64 {
        self.explicit("poisson_warp").unwrap_or_else(|| {
            self.out.warnings.push(format!(
                "poisson_warp: no standard measures it; using {DEFAULT_POISSON} (plain wovens: 0.1–0.3). Add \
                 `poisson_warp = …` to the fabric file to set it"
            ));
            self.push("poisson_warp", float(DEFAULT_POISSON), "default: no standard measures it".into(), true);
            DEFAULT_POISSON
        })
    }

    fn bias(&mut self, strip: impl Fn(f64) -> BiasStrip) -> Result<(), SheetError> {
        let Some(cant) = self.sheets.cantilever.clone() else { return Ok(()) };
        let Some((c, field)) = Self::cantilever_length(&cant, "bias")? else { return Ok(()) };
        let width = cant.si("strip_width").unwrap_or(STANDARD_STRIP_WIDTH);
        let strip = strip(width);
        let b45 = plate_rigidity_for_bending_length(&strip, c).map_err(|e| SheetError::Inconsistent {
            fields: cant.quote(&field),
            message: e.to_string(),
        })?;
        let plate = rigidity_for_bending_length(c, weight_per_area(strip.areal_density));
        let width_text = if cant.si("strip_width").is_some() { cant.quote("strip_width") } else { "the standard's 25 mm strip".into() };
        let source = format!(
            "{} on {width_text}: the plate rigidity whose free strip reads it (W·g·c³ = {:.3} µN·m would ignore the \
             strip's anticlastic relaxation; docs/fabric-sheets.md, Bias)",
            cant.quote(&field),
            plate * 1e6
        );
        self.push("bending_bias", float(b45), source, false);
        Ok(())
    }
}

/// The fabric keys the sheets give. `explicit` holds the keys written directly in the
/// fabric file: they win, and they feed the conversions that need them (the bias).
pub fn derive(sheets: &Sheets, explicit: &toml::Table) -> Result<Import, SheetError> {
    if let Some(arcsim) = &sheets.arcsim {
        let mut import = super::arcsim::project::derive(&arcsim.material(), &arcsim.origin(), explicit);
        if let Some(look) = &arcsim.appearance {
            let source = format!("{}: the material file's \"appearance\"", arcsim.origin());
            import.derived.push(Derived { key: "appearance", value: look.clone(), source, default: false, section: None });
        }
        return Ok(import);
    }
    let mut d = Deriver { sheets, explicit, out: Import::default() };
    let rho = d.areal_density()?;
    d.thickness(rho);
    let [bx, by] = d.bending(rho)?;
    let shear = d.shear();
    let [ex, ey] = d.tensile()?;
    let nu = d.poisson();
    if d.explicit("bending_bias").is_none() {
        let axial = crate::reference::off_axis_modulus(ex, ey, shear, nu, std::f64::consts::FRAC_PI_4);
        d.bias(|width| BiasStrip {
            areal_density: rho,
            bending_warp: bx,
            bending_weft: by,
            poisson_warp: nu,
            axial_modulus: axial,
            width,
        })?;
    }
    Ok(d.out)
}

/// What [`expand_sheets`] took out of a fabric table and what it put in.
#[derive(Debug, Clone, Default)]
pub struct Expanded {
    /// The sheet sections, as read (empty when the table had none).
    pub sheets: Sheets,
    /// The keys the sheets gave, with their sources.
    pub import: Import,
    /// Defaults used and disagreements found, one sentence each: the import's own
    /// warnings and one for each key the table gives otherwise than the sheet.
    pub warnings: Vec<String>,
}

/// Replaces the sheet sections (`[kes]`, `[fast]`, `[cantilever]`, `[arcsim]`) of a fabric table by
/// the fabric keys they give. A key already in the table wins; a warning says so where the
/// sheet disagrees with it.
pub fn expand_sheets(table: &mut toml::Table) -> Result<Expanded, SheetError> {
    let sheets = Sheets::take(table)?;
    if sheets.is_empty() {
        return Ok(Expanded { sheets, ..Expanded::default() });
    }
    let import = derive(&sheets, table)?;
    let warnings = apply(table, &import);
    Ok(Expanded { sheets, import, warnings })
}

/// Inserts the derived keys into a fabric table that has no sheet sections left; keys
/// already there win. Returns the import's warnings and one for each key the sheet
/// disagrees with.
fn apply(table: &mut toml::Table, import: &Import) -> Vec<String> {
    let mut warnings = import.warnings.clone();
    for d in &import.derived {
        match table.get(d.key) {
            None => {
                table.insert(d.key.to_string(), d.value.clone());
            }
            Some(existing) if existing != &d.value => warnings.push(format!(
                "fabric.{} is given both as a key and by the sheet ({}); the key is used",
                d.key, d.source
            )),
            Some(_) => {}
        }
    }
    warnings
}

/// Moves the sheet sections a scene writes under `[fabric]` (or sets with
/// `--set fabric.kes.B_warp=…`) into the fabric file's table, field by field, so that the
/// sheet is converted once with the scene's changes in it.
pub fn merge_scene_sheets(file: &mut toml::Table, scene: &mut toml::Table) {
    for kind in SheetKind::ALL {
        if !scene.get(kind.section()).is_some_and(toml::Value::is_table) {
            // Not a table: left for `expand_sheets` to report with the section's name.
            continue;
        }
        let Some(toml::Value::Table(changes)) = scene.remove(kind.section()) else { continue };
        let entry = file.entry(kind.section()).or_insert_with(|| toml::Value::Table(toml::Table::new()));
        if let Some(section) = entry.as_table_mut() {
            section.extend(changes);
        }
    }
}
