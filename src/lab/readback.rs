//! The round trip: run the virtual tests on a fabric imported from a sheet and set what
//! they read beside what the sheet says.

use super::{CantileverTest, Direction, KesTensile, LabError, PureBending, ShearTest, cantilever_bending_length, kes_tensile, pure_bending, shear};
use crate::fabric::bias::STANDARD_STRIP_WIDTH;
use crate::fabric::derived::{DEFAULT_LT, FAST_SHEAR_CONSTANT, Import, KES_FM};
use crate::fabric::sheet::{SheetKind, Sheets};
use crate::fabric::tensile::FAST_LOADS;
use crate::fabric::units::{GF_CM_PER_CM2, GF_CM2_PER_CM, GF_PER_CM_DEG};
use crate::settings::FabricConfig;
use super::report::{Property, ReadBack};
use std::collections::BTreeMap;

/// Virtual tests already run on the fabric, handed to [`readback_with`] so that it reads
/// them instead of running them again (the fabric card runs them all in parallel first).
/// They must have been run on the same fabric.
#[derive(Debug, Clone, Default)]
pub struct LabRuns {
    pub tensile: BTreeMap<Direction, KesTensile>,
    pub bending: BTreeMap<Direction, PureBending>,
    pub shear: Option<ShearTest>,
    pub cantilever: Vec<CantileverTest>,
}

/// The virtual tests' results, each run once whatever asks for it.
struct Runs<'a> {
    fabric: &'a FabricConfig,
    done: LabRuns,
}

impl Runs<'_> {
    fn tensile(&mut self, d: Direction) -> Result<&KesTensile, LabError> {
        if !self.done.tensile.contains_key(&d) {
            self.done.tensile.insert(d, kes_tensile(self.fabric, d)?);
        }
        Ok(&self.done.tensile[&d])
    }

    fn bending(&mut self, d: Direction) -> Result<&PureBending, LabError> {
        if !self.done.bending.contains_key(&d) {
            self.done.bending.insert(d, pure_bending(self.fabric, d)?);
        }
        Ok(&self.done.bending[&d])
    }

    fn shear(&mut self) -> Result<&ShearTest, LabError> {
        if self.done.shear.is_none() {
            self.done.shear = Some(shear(self.fabric)?);
        }
        Ok(self.done.shear.as_ref().expect("just run"))
    }

    /// The bending length of a strip `width` wide cut along `d`.
    fn cantilever(&mut self, d: Direction, width: f64) -> Result<f64, LabError> {
        if let Some(t) = self.done.cantilever.iter().find(|t| t.direction == d && t.strip_width == width) {
            return Ok(t.bending_length);
        }
        let t = cantilever_bending_length(self.fabric, d, width)?;
        let c = t.bending_length;
        self.done.cantilever.push(t);
        Ok(c)
    }
}

/// Which section supplied a fabric key (None for defaults and keys written directly).
fn supplier(import: &Import, key: &str) -> Option<SheetKind> {
    import.get(key).filter(|d| !d.default).and_then(|d| d.section)
}

/// Runs the virtual tests that check each value the fabric took from its sheets, on the
/// fabric as loaded (`fabric`), and returns the table of sheet against reading.
pub fn readback(sheets: &Sheets, import: &Import, fabric: &FabricConfig) -> Result<ReadBack, LabError> {
    readback_with(sheets, import, fabric, LabRuns::default())
}

/// [`readback`], reading the tests in `done` instead of running them again.
pub fn readback_with(sheets: &Sheets, import: &Import, fabric: &FabricConfig, done: LabRuns) -> Result<ReadBack, LabError> {
    if let Some(arcsim) = &sheets.arcsim {
        return super::arcsim::readback(&arcsim.material(), fabric, super::arcsim::Scope::All);
    }
    let mut runs = Runs { fabric, done };
    let mut out = ReadBack::default();
    let mut push = |field: String, unit, sheet, measured, test, tolerance| {
        out.properties.push(Property { field, unit, sheet, measured, test, tolerance, unheld: None });
    };
    for (dir, d) in [("warp", Direction::Warp), ("weft", Direction::Weft)] {
        let tensile_key = format!("tensile_{dir}");
        match (supplier(import, &tensile_key), &sheets.kes, &sheets.fast) {
            (Some(SheetKind::Kes), Some(kes), _) => {
                let fm = kes.si("Fm").unwrap_or(KES_FM);
                let (emt, lt, wt) = (kes.si(&format!("EMT_{dir}")), kes.si(&format!("LT_{dir}")), kes.si(&format!("WT_{dir}")));
                // The sheet's three numbers, completing a missing one by LT = WT/(Fm·EMT/2).
                let (emt, lt, wt) = match (emt, lt, wt) {
                    (Some(e), Some(l), w) => (e, l, w.unwrap_or(l * fm * e / 2.0)),
                    (Some(e), None, Some(w)) => (e, w / (fm * e / 2.0), w),
                    (None, Some(l), Some(w)) => (2.0 * w / (l * fm), l, w),
                    (Some(e), None, None) => (e, DEFAULT_LT, DEFAULT_LT * fm * e / 2.0),
                    _ => continue,
                };
                let t = runs.tensile(d)?;
                push(format!("kes.EMT_{dir}"), "%", 100.0 * emt, t.emt_percent(), "KES tensile", 0.03);
                push(format!("kes.LT_{dir}"), "", lt, t.lt, "KES tensile", 0.03);
                push(format!("kes.WT_{dir}"), "gf·cm/cm²", wt / GF_CM_PER_CM2, t.wt_kes(), "KES tensile", 0.03);
            }
            (Some(SheetKind::Fast), _, Some(fast)) => {
                for (name, load) in ["E5", "E20", "E100"].into_iter().zip(FAST_LOADS) {
                    let field = format!("{name}_{dir}");
                    let Some(e) = fast.si(&field) else { continue };
                    let t = runs.tensile(d)?;
                    let measured = t.strain_at(load).unwrap_or(f64::NAN);
                    push(format!("fast.{field}"), "%", 100.0 * e, 100.0 * measured, "KES tensile", 0.03);
                }
            }
            _ => {}
        }
        let bending_key = format!("bending_{dir}");
        match supplier(import, &bending_key) {
            Some(SheetKind::Kes) => {
                let b = sheets.kes.as_ref().and_then(|k| k.si(&format!("B_{dir}"))).expect("the supplier has it");
                push(format!("kes.B_{dir}"), "gf·cm²/cm", b / GF_CM2_PER_CM, runs.bending(d)?.kes(), "pure bending", 0.02);
            }
            Some(SheetKind::Fast) => {
                let fast = sheets.fast.as_ref().expect("the supplier exists");
                if let Some(c) = fast.si(&format!("C_{dir}")) {
                    let c_virtual = runs.cantilever(d, STANDARD_STRIP_WIDTH)?;
                    push(format!("fast.C_{dir}"), "mm", 1e3 * c, 1e3 * c_virtual, "cantilever", 0.03);
                } else if let Some(b) = fast.si(&format!("B_{dir}")) {
                    push(format!("fast.B_{dir}"), "µN·m", 1e6 * b, 1e6 * runs.bending(d)?.rigidity, "pure bending", 0.02);
                }
            }
            Some(SheetKind::Cantilever) => {
                let cant = sheets.cantilever.as_ref().expect("the supplier exists");
                push_cantilever(&mut push, cant, &mut runs, dir, d)?;
            }
            None => {}
        }
    }
    if supplier(import, "bending_bias") == Some(SheetKind::Cantilever) {
        let cant = sheets.cantilever.as_ref().expect("the supplier exists");
        push_cantilever(&mut push, cant, &mut runs, "bias", Direction::Bias)?;
    }
    match supplier(import, "shear_modulus") {
        Some(SheetKind::Kes) => {
            let kes = sheets.kes.as_ref().expect("the supplier exists");
            let g: Vec<f64> = ["G_warp", "G_weft"].iter().filter_map(|f| kes.si(f)).collect();
            let sheet = g.iter().sum::<f64>() / g.len() as f64;
            push("kes.G".into(), "gf/(cm·deg)", sheet / GF_PER_CM_DEG, runs.shear()?.kes(), "shear", 0.05);
        }
        Some(SheetKind::Fast) => {
            let fast = sheets.fast.as_ref().expect("the supplier exists");
            let (field, sheet) = match (fast.si("G"), fast.si("EB5")) {
                (Some(g), _) => ("fast.G", g),
                (None, Some(eb5)) => ("fast.EB5 → 123/EB5", FAST_SHEAR_CONSTANT / (100.0 * eb5)),
                (None, None) => unreachable!("the supplier gave a shear value"),
            };
            push(field.into(), "N/m", sheet, runs.shear()?.modulus, "shear", 0.05);
        }
        _ => {}
    }
    Ok(out)
}

fn push_cantilever(
    push: &mut impl FnMut(String, &'static str, f64, f64, &'static str, f64),
    cant: &crate::fabric::sheet::Section,
    runs: &mut Runs,
    dir: &str,
    d: Direction,
) -> Result<(), LabError> {
    let c = match (cant.si(&format!("c_{dir}")), cant.si(&format!("overhang_{dir}"))) {
        (Some(c), _) => c,
        (None, Some(o)) => 0.5 * o,
        (None, None) => return Ok(()),
    };
    let width = cant.si("strip_width").unwrap_or(STANDARD_STRIP_WIDTH);
    let bending_length = runs.cantilever(d, width)?;
    push(format!("cantilever.c_{dir}"), "mm", 1e3 * c, 1e3 * bending_length, "cantilever", 0.03);
    Ok(())
}
