//! Seams for a pattern file, which holds none: a seams file the designer writes (piece,
//! point to point, piece, point to point), and suggestions that pair edges by the pieces'
//! names and matching lengths and notches, printed for the designer to accept into a seams
//! file, never applied by themselves (docs/garments.md, "Seams for a DXF pattern").
//!
//! A seams file:
//!
//! ```toml
//! # Each seam sews a stretch of one panel's outline to a stretch of another's, `from` to
//! # `from` and `to` to `to`; points are corners c1, c2, ... and notches n1, n2, ...
//! [[seams]]
//! a = { piece = "front", from = "c2", to = "c3" }
//! b = { piece = "back-left", from = "c1", to = "c4" }
//!
//! # Optional: where pieces go, when their names do not say it.
//! [placement]
//! front = ["front"]
//! back = ["back"]
//! sleeves = []
//! top = "waist"      # or "shoulder"
//! ```
//!
//! A stretch runs the shorter way round the outline unless `way = "ccw"` (along the
//! outline, counter-clockwise as drawn) or `"cw"` says otherwise.

use super::panels::{Arrangement, PiecePanel, Role, Top};
use crate::garment::GarmentError;
use crate::garment::pattern::PanelConfig;
use crate::garment::place::Placement;
use crate::garment::seams::SeamConfig;
use crate::garment::stretch::{Outline, Stretch, seams as stretch_seams};
use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};
use std::fmt::Write;

/// A seams file.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeamsFile {
    #[serde(default)]
    pub seams: Vec<SeamSpec>,
    #[serde(default, skip_serializing_if = "PlacementSpec::is_empty")]
    pub placement: PlacementSpec,
}

/// One seam: stretch `a` sewn to stretch `b`, first points together.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeamSpec {
    pub a: SideSpec,
    pub b: SideSpec,
}

/// A stretch of a panel's outline between two named points.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SideSpec {
    /// The panel (a piece's name as `rosette pattern seams` lists it: `back-right`).
    pub piece: String,
    pub from: String,
    pub to: String,
    /// `ccw` or `cw`; the shorter way round where absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub way: Option<Way>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Way {
    Ccw,
    Cw,
}

/// `[placement]`: pieces (or panels) by role, and the level of their tops.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlacementSpec {
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub front: Vec<String>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub back: Vec<String>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sleeves: Vec<String>,
    /// `waist` or `shoulder`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub top: Option<String>,
}

impl PlacementSpec {
    fn is_empty(&self) -> bool {
        self.front.is_empty() && self.back.is_empty() && self.sleeves.is_empty() && self.top.is_none()
    }

    /// Added to `arrangement` (whose own choice of the top wins).
    pub fn merge_into(&self, arrangement: &mut Arrangement) -> Result<(), String> {
        arrangement.front.extend(self.front.iter().cloned());
        arrangement.back.extend(self.back.iter().cloned());
        arrangement.sleeves.extend(self.sleeves.iter().cloned());
        if arrangement.top.is_none() {
            arrangement.top = match self.top.as_deref() {
                None => None,
                Some("waist") => Some(Top::Waist),
                Some("shoulder") => Some(Top::Shoulder),
                Some(other) => return Err(format!("placement.top = \"{other}\": use \"waist\" (skirts, trousers) or \"shoulder\" (tops, dresses)")),
            };
        }
        Ok(())
    }
}

/// Reads a seams file's text (from `source`).
pub fn parse(text: &str, source: &str) -> Result<SeamsFile, GarmentError> {
    let deserializer = toml::Deserializer::parse(text).map_err(|e| GarmentError::new(format!("{source}: not valid TOML: {e}")))?;
    serde_path_to_error::deserialize(deserializer).map_err(|e| {
        let path = e.path().to_string();
        GarmentError::new(format!("{source}: {}{}", if path == "." { String::new() } else { format!("{path}: ") }, e.inner().message()))
    })
}

/// The garment seams a seams file gives on `panels`: each of its seams as one or more
/// `[garment]` seams (cut where a stretch turns a corner). Messages name the seam's entry.
pub fn resolve(file: &SeamsFile, panels: &[PanelConfig], source: &str) -> Result<Vec<SeamConfig>, GarmentError> {
    let outlines: Vec<Outline> = panels.iter().map(Outline::new).collect::<Result<_, _>>()?;
    let mut all = Vec::new();
    for (i, seam) in file.seams.iter().enumerate() {
        let key = format!("{source}: seams[{i}]");
        let stretch = |side: &SideSpec, which: &str| -> Result<Stretch, GarmentError> {
            let bad = |m: String| GarmentError::new(format!("{key}.{which}: {m}"));
            let p = panels.iter().position(|p| p.name == side.piece).ok_or_else(|| {
                let names: Vec<&str> = panels.iter().map(|p| p.name.as_str()).collect();
                bad(format!("no piece '{}'; the pieces are {}", side.piece, names.join(", ")))
            })?;
            let outline = &outlines[p];
            let point = |name: &str| {
                outline.point(&panels[p], name).ok_or_else(|| {
                    let names: Vec<String> = outline.point_names(&panels[p]).into_iter().map(|n| n.0).collect();
                    bad(format!("piece '{}' has no point '{name}'; its points are {}", side.piece, names.join(", ")))
                })
            };
            let (from, to) = (point(&side.from)?, point(&side.to)?);
            if (from - to).abs() < 1e-9 {
                return Err(bad(format!("from = to = '{}': a stretch runs between two different points", side.from)));
            }
            Ok(match side.way {
                None => Stretch::shorter(p, from, to, outline.perimeter),
                Some(way) => Stretch { panel: p, from, to, counter_clockwise: way == Way::Ccw },
            })
        };
        let (a, b) = (stretch(&seam.a, "a")?, stretch(&seam.b, "b")?);
        let parts = stretch_seams(panels, &outlines, a, b).map_err(|e| GarmentError::new(format!("{key}: {}", e.message)))?;
        all.extend(parts);
    }
    Ok(all)
}

/// A suggested seam: two whole edges, why they were paired, and how far apart they start.
#[derive(Debug, Clone)]
pub struct Suggestion {
    pub seam: SeamSpec,
    pub lengths: [f64; 2],
    pub notches: usize,
    /// Mean distance between the points the seam would join, where the panels start, cm.
    pub apart: f64,
}

/// An edge as suggestions compare it: its panel and index, length (cm) and its notches'
/// distances from its start (cm).
struct Edge {
    panel: usize,
    edge: usize,
    length: f64,
    notches: Vec<f64>,
}

/// How near its panel's highest point both ends of an edge lie for it to be the panel's
/// top (a waist, a neckline, a shoulder), garment units (cm).
const TOP_BAND: f64 = 3.0;

/// Edges to pair: sides of different panels whose lengths agree within 2 % (or 5 mm),
/// whose notches lie at the same distances from the ends joined (within 5 mm or 2 %), that
/// are neither at the garment's bottom (a hem) nor at a panel's top (a waist or a neckline;
/// where the tops go to the shoulders, a front's top may pair with a back's, a shoulder
/// seam), paired nearest first by where the panels start around the form. `panels` are
/// placed ([`super::panels::arrange`]) with their tops at `top`.
pub fn suggest(panels: &[PiecePanel], top: Top) -> Result<Vec<Suggestion>, GarmentError> {
    let configs: Vec<&PanelConfig> = panels.iter().map(|p| &p.panel).collect();
    let mut edges = Vec::new();
    // Each edge's placed points, 11 along it, cm.
    let mut placed: Vec<Vec<DVec3>> = Vec::new();
    let (mut lowest, mut highest) = (f64::INFINITY, f64::NEG_INFINITY);
    // Each panel's highest placed point, cm.
    let mut tops = vec![f64::NEG_INFINITY; configs.len()];
    for (p, panel) in configs.iter().enumerate() {
        let curves = panel.curves(1.0)?;
        let (lo, hi) = crate::garment::flat::bounds(&curves.iter().flat_map(|c| c.points.iter().copied()).collect::<Vec<_>>());
        let anchor = panel.anchor.map_or(DVec2::new(0.5 * (lo.x + hi.x), hi.y), DVec2::from_array);
        let place = Placement::new(&panel.placement, anchor, DVec2::ZERO, 1.0);
        let positions = panel.notch_positions(&curves, 1.0)?;
        for (e, curve) in curves.iter().enumerate() {
            let points: Vec<DVec3> = (0..=10).map(|k| place.position(curve.at(curve.length() * k as f64 / 10.0))).collect();
            for q in &points {
                lowest = lowest.min(q.z);
                highest = highest.max(q.z);
                tops[p] = tops[p].max(q.z);
            }
            placed.push(points);
            let notches = positions.iter().filter(|(edge, _)| *edge == e).map(|(_, at)| *at).collect();
            edges.push(Edge { panel: p, edge: e, length: curve.length(), notches });
        }
    }
    let ends = |k: usize| [placed[k][0].z, placed[k][10].z];
    let hem = |k: usize| ends(k).iter().all(|&z| z < lowest + 3.0);
    let at_top = |k: usize| ends(k).iter().all(|&z| z > highest - 1.0 || z > tops[edges[k].panel] - TOP_BAND);
    // A shoulder seam: the tops of a front and a back, where the tops go to the shoulders.
    let shoulder = |i: usize, j: usize| {
        let roles = [panels[edges[i].panel].role, panels[edges[j].panel].role];
        top == Top::Shoulder && roles.contains(&Role::Front) && roles.contains(&Role::Back)
    };
    let pairable = |i: usize, j: usize| !hem(i) && !hem(j) && (!(at_top(i) || at_top(j)) || (at_top(i) && at_top(j) && shoulder(i, j)));
    let mut candidates: Vec<(f64, usize, usize, bool)> = Vec::new();
    for i in 0..edges.len() {
        for j in i + 1..edges.len() {
            let (a, b) = (&edges[i], &edges[j]);
            if a.panel == b.panel || !pairable(i, j) {
                continue;
            }
            let tolerance = (0.02 * a.length.max(b.length)).max(0.5);
            if (a.length - b.length).abs() > tolerance || a.notches.len() != b.notches.len() {
                continue;
            }
            for same in [false, true] {
                // Same: a's start meets b's start; opposite: a's start meets b's end.
                let mut theirs: Vec<f64> = b.notches.iter().map(|&n| if same { n } else { b.length - n }).collect();
                theirs.sort_by(f64::total_cmp);
                let notches_agree = a.notches.iter().zip(&theirs).all(|(x, y)| (x - y).abs() <= tolerance.max(0.5));
                if !notches_agree {
                    continue;
                }
                let apart = (0..=10).map(|k| placed[i][k].distance(placed[j][if same { k } else { 10 - k }])).sum::<f64>() / 11.0;
                candidates.push((apart, i, j, same));
            }
        }
    }
    candidates.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut used = vec![false; edges.len()];
    let mut out = Vec::new();
    for (apart, i, j, same) in candidates {
        if used[i] || used[j] || apart > 60.0 {
            continue;
        }
        used[i] = true;
        used[j] = true;
        let side = |k: usize, reverse: bool| -> SideSpec {
            let e = &edges[k];
            let panel = configs[e.panel];
            let start = corner_of(panel, e.edge);
            let end = corner_of(panel, (e.edge + 1) % panel.edges.len());
            let perimeter: f64 = edges.iter().filter(|x| x.panel == e.panel).map(|x| x.length).sum();
            // The edge is the counter-clockwise way from its start to its end; say so where
            // it is not the shorter way.
            let way = (e.length > 0.5 * perimeter - 1e-9).then_some(if reverse { Way::Cw } else { Way::Ccw });
            let (from, to) = if reverse { (end, start) } else { (start, end) };
            SideSpec { piece: panel.name.clone(), from, to, way }
        };
        out.push(Suggestion {
            seam: SeamSpec { a: side(i, false), b: side(j, !same) },
            lengths: [edges[i].length, edges[j].length],
            notches: edges[i].notches.len(),
            apart,
        });
    }
    Ok(out)
}

/// The name of the corner where edge `k` of `panel` starts: `cK` for an edge `eK`.
fn corner_of(panel: &PanelConfig, k: usize) -> String {
    let name = &panel.edges[k].name;
    name.strip_prefix('e').filter(|n| n.parse::<u32>().is_ok()).map_or_else(|| name.clone(), |n| format!("c{n}"))
}

/// A seams file holding `suggestions`, each with a comment saying why, and the placement
/// the import took, for the designer to read, correct and keep.
pub fn suggestions_text(source: &str, panels: &[PiecePanel], suggestions: &[Suggestion]) -> String {
    let mut text = format!(
        "# Seams suggested for {} by `rosette pattern seams`: edges of equal length whose notches match,\n\
         # nearest first where the pieces start around the form. Check each one, delete or correct\n\
         # what is wrong, and keep the file beside the pattern as NAME.seams.toml (or give it with\n\
         # --seams); nothing is sewn that this file does not say.\n#\n",
        source.replace(['\n', '\r'], " ")
    );
    for p in panels {
        let outline = Outline::new(&p.panel);
        let points = outline.map(|o| o.point_names(&p.panel).into_iter().map(|(n, at)| format!("{n} {at:.1}")).collect::<Vec<_>>().join(", ")).unwrap_or_default();
        let _ = writeln!(text, "# {} ({}{}): points at cm along its outline: {points}", p.panel.name, role_name(p.role), if p.mirrored { ", mirrored" } else { "" });
    }
    if suggestions.is_empty() {
        text.push_str("#\n# No two edges match; write the seams by hand.\n");
    }
    for s in suggestions {
        let direction = |d: &SideSpec| format!("{{ piece = \"{}\", from = \"{}\", to = \"{}\"{} }}", d.piece, d.from, d.to, d.way.map_or(String::new(), |w| format!(", way = \"{}\"", if w == Way::Ccw { "ccw" } else { "cw" })));
        let _ = write!(
            text,
            "\n# {:.1} cm and {:.1} cm (difference {:.1} mm), {} notch(es); {:.0} cm apart where they start.\n[[seams]]\na = {}\nb = {}\n",
            s.lengths[0],
            s.lengths[1],
            10.0 * (s.lengths[0] - s.lengths[1]).abs(),
            s.notches,
            s.apart,
            direction(&s.seam.a),
            direction(&s.seam.b)
        );
    }
    text
}

fn role_name(role: Role) -> &'static str {
    match role {
        Role::Front => "front",
        Role::Back => "back",
        Role::Sleeve => "sleeve",
        Role::Side => "side",
    }
}
