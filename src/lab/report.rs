//! The round trip's report: each sheet property beside its virtual reading.

/// One property of a sheet and its virtual reading, both in the sheet's unit.
#[derive(Debug, Clone, PartialEq)]
pub struct Property {
    /// The sheet field, e.g. `kes.EMT_warp`.
    pub field: String,
    pub unit: &'static str,
    /// What the sheet says (computed by the standard's formula where the sheet gives the
    /// property through others, e.g. WT = LT·Fm·EMT/2).
    pub sheet: f64,
    /// What the virtual test read.
    pub measured: f64,
    /// The test that read it.
    pub test: &'static str,
    /// Relative tolerance the round trip is held to (tensile 3 %, bending 2 %, shear 5 %,
    /// bending lengths 3 %).
    pub tolerance: f64,
    /// Why a value is read and reported but not held to the tolerance (an ARCSim sample
    /// the projection drops); None for a value held.
    pub unheld: Option<String>,
}

impl Property {
    /// (measured − sheet)/sheet.
    pub fn error(&self) -> f64 {
        (self.measured - self.sheet) / self.sheet
    }

    pub fn passes(&self) -> bool {
        self.unheld.is_some() || self.error().abs() <= self.tolerance
    }

    /// Whether the value is held to its tolerance.
    pub fn held(&self) -> bool {
        self.unheld.is_none()
    }
}

/// Every sheet property that the fabric's keys came from, read back.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReadBack {
    pub properties: Vec<Property>,
}

impl ReadBack {
    pub fn all_pass(&self) -> bool {
        self.properties.iter().all(Property::passes)
    }

    /// A plain-text table: field, sheet, virtual, error, tolerance.
    pub fn table(&self) -> String {
        let mut out = format!("{:<22} {:>12} {:>12} {:>8} {:>6}  {}\n", "sheet field", "sheet", "virtual", "error", "tol.", "unit (test)");
        for p in &self.properties {
            let tolerance = if p.held() { format!("{:>5.0}%", 100.0 * p.tolerance) } else { "    -".into() };
            let flag = match (&p.unheld, p.passes()) {
                (Some(why), _) => format!("  not held: {why}"),
                (None, true) => String::new(),
                (None, false) => "  OUTSIDE".into(),
            };
            out += &format!(
                "{:<22} {:>12.5} {:>12.5} {:>+7.2}% {tolerance}  {} ({}){flag}\n",
                p.field,
                p.sheet,
                p.measured,
                100.0 * p.error(),
                p.unit,
                p.test,
            );
        }
        out
    }
}

