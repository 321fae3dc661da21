//! Pattern CAD files: DXF in the AAMA / ASTM D6673 convention, the one format Gerber
//! AccuMark, Lectra Modaris, Optitex, CLO, Marvelous Designer, Seamly2D and Valentina all
//! exchange (docs/garments.md, "Patterns from pattern CAD").
//!
//! The convention, as this reader takes it:
//! - one BLOCK per pattern piece, inserted by an INSERT (whose place, scale and rotation
//!   are applied); without INSERTs, every block that holds a cut line is a piece;
//! - layers by number: 1 the cut line (a closed polyline) and the piece's text, 14 the sew
//!   line, 8 internal lines (in older AAMA files also the sew line, as a closed polyline
//!   inside the cut line), 7 the grain line, 4 notches (POINTs with the depth in z, the
//!   angle into the piece in group 50 and the width in group 39; or, in AAMA files, short
//!   LINEs from the cut line inwards), 80 to 83 T, castle, check and U notches, 13 drill
//!   holes, 6 a mirror (fold) line; 2, 3, 15 and the validation copies 84 to 87 are not read;
//! - text `Keyword: value` on layer 1: `Piece Name:`, `Size:`, `Quantity:` in a block,
//!   `Units: METRIC` (millimetres) or `ENGLISH` (inches) and `Style Name:` outside;
//! - R12 files carry no unit in their header; R2000 and later may (`$INSUNITS`).
//!
//! [`read`] turns a file into [`DxfPattern`]: each piece's outline (its sew line where the
//! file has one), grain, notches and the facts kept about it, in millimetres, every
//! refusal naming the piece and the fix. [`panels`] turns pieces into a garment's panels
//! and places them around the form; [`write`] writes a garment back in the same
//! convention.

pub mod import;
pub mod panels;
mod read;
pub mod seams;
pub mod write;

pub use read::{MAX_OUTLINE_POINTS, MAX_PIECE_ENTITIES, MAX_PIECE_SIZE, read};

use glam::DVec2;

/// The length unit a pattern file is drawn in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LengthUnit {
    Mm,
    Cm,
    In,
}

impl LengthUnit {
    /// Millimetres in one unit.
    pub fn mm(self) -> f64 {
        match self {
            LengthUnit::Mm => 1.0,
            LengthUnit::Cm => 10.0,
            LengthUnit::In => 25.4,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            LengthUnit::Mm => "mm",
            LengthUnit::Cm => "cm",
            LengthUnit::In => "in",
        }
    }

    /// `mm`, `cm` or `in` (also `inch`, `inches`).
    pub fn parse(text: &str) -> Option<Self> {
        match text.trim().to_ascii_lowercase().as_str() {
            "mm" => Some(LengthUnit::Mm),
            "cm" => Some(LengthUnit::Cm),
            "in" | "inch" | "inches" => Some(LengthUnit::In),
            _ => None,
        }
    }
}

/// How a file is read.
#[derive(Debug, Clone, Default)]
pub struct ReadOptions {
    /// The unit to read the file in, whatever it says (a file whose text or header names
    /// the wrong unit).
    pub units: Option<LengthUnit>,
    /// The warp's angle, degrees from a piece's x axis, for pieces without a grain line;
    /// without it such a piece is refused.
    pub grain_deg: Option<f64>,
}

/// A notch's shape, from its layer (4: slit or V, 80: T, 81: castle, 82: check, 83: U).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NotchShape {
    Slit,
    V,
    T,
    Castle,
    Check,
    U,
}

impl NotchShape {
    /// The ASTM layer a notch of this shape is written on.
    pub fn layer(self) -> &'static str {
        match self {
            NotchShape::Slit | NotchShape::V => "4",
            NotchShape::T => "80",
            NotchShape::Castle => "81",
            NotchShape::Check => "82",
            NotchShape::U => "83",
        }
    }
}

/// A notch, moved onto the piece's outline.
#[derive(Debug, Clone, PartialEq)]
pub struct Notch {
    /// Distance along the outline from its first point, mm.
    pub at: f64,
    pub shape: NotchShape,
    /// Depth into the piece, mm (0 where the file gives none).
    pub depth: f64,
}

/// One pattern piece as the file gives it, in millimetres, y up.
#[derive(Debug, Clone)]
pub struct Piece {
    /// The piece's name: its `Piece Name:` text, else its block's name.
    pub name: String,
    /// The block it was read from.
    pub block: String,
    /// How many are cut (`Quantity:`; 1 where the file says nothing).
    pub quantity: u32,
    /// `Size:`, where given.
    pub size: Option<String>,
    /// The outline Rosette sews: the sew line where the file has one, else the cut line;
    /// counter-clockwise, its first point not repeated at the end.
    pub outline: Vec<DVec2>,
    /// Whether `outline` is the file's sew line (else it is the cut line).
    pub sew_line: bool,
    /// The cut line, counter-clockwise.
    pub cut_line: Vec<DVec2>,
    /// The width between cut line and sew line, mm: least, mean and most over the sew
    /// line's points. None without a sew line.
    pub seam_allowance: Option<[f64; 3]>,
    /// The warp's direction, degrees counter-clockwise from the x axis, in [0, 180).
    pub grain_deg: f64,
    /// Whether the file gives the grain line (else `grain_deg` is the option's).
    pub grain_given: bool,
    pub notches: Vec<Notch>,
    /// Drill holes (layer 13), mm.
    pub drill_holes: Vec<DVec2>,
    /// Internal lines drawn on the piece (layer 8, and 11's cut-outs), counted.
    pub internal_lines: usize,
}

/// A pattern file read: its pieces, the unit it was read in and what the reader chose.
#[derive(Debug, Clone)]
pub struct DxfPattern {
    pub pieces: Vec<Piece>,
    pub units: LengthUnit,
    /// `Style Name:`, where given.
    pub style: Option<String>,
    /// What the reader assumed or left out, for the user to know.
    pub notes: Vec<String>,
}

/// The first bytes of a binary DXF file.
pub const BINARY_SENTINEL: &[u8] = b"AutoCAD Binary DXF\r\n\x1a\0";
