//! Seams and attachments: which edge (or stretch of an edge) joins which, and where every
//! edge is cut into vertices so that the two sides of each seam have matching ones.

use super::GarmentError;
use super::mesh::{Cuts, even_cuts};
use serde::{Deserialize, Serialize};

/// Which ends of the two sides meet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Direction {
    /// The start of side a meets the end of side b: two neighbouring panels, both outlined
    /// counter-clockwise from the right side, sewn right side out (the usual seam).
    Opposite,
    /// Start meets start.
    Same,
}

/// `[[garment.seams]]`: joins side a to side b.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeamConfig {
    /// `panel.edge`.
    pub a: String,
    pub b: String,
    pub direction: Direction,
    /// Only this stretch of a's edge, [from, to] along it from its start, in the
    /// garment's units (default: all of it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub a_span: Option<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub b_span: Option<[f64; 2]>,
}

/// `[[garment.attachments]]`: an edge held to the form.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AttachmentConfig {
    /// `panel.edge`.
    pub edge: String,
    /// Pinned where it starts (a hanger's clamp), instead of pulled onto the form.
    #[serde(default)]
    pub pin: bool,
    /// Pulled onto the form's section at this named level of a generated form: `waist`,
    /// `hip` or `bust`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub level: Option<String>,
    /// Pulled onto the form's section at this height, in the garment's units.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<f64>,
}

/// One side of a seam, resolved: panel and edge index, and the stretch in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Side {
    pub panel: usize,
    pub edge: usize,
    pub from: f64,
    pub to: f64,
}

/// Finds `panel.edge` among `names` (each panel's name and its edges' names).
pub fn resolve(key: &str, text: &str, names: &[(String, Vec<String>)]) -> Result<(usize, usize), GarmentError> {
    let (panel, edge) = text
        .split_once('.')
        .ok_or_else(|| GarmentError::new(format!("{key} = \"{text}\" must name a panel and an edge as \"panel.edge\"")))?;
    let p = names.iter().position(|(n, _)| n == panel).ok_or_else(|| {
        let known: Vec<&str> = names.iter().map(|(n, _)| n.as_str()).collect();
        GarmentError::new(format!("{key} = \"{text}\": no panel '{panel}'; the panels are {}", known.join(", ")))
    })?;
    let e = names[p].1.iter().position(|n| n == edge).ok_or_else(|| {
        GarmentError::new(format!("{key} = \"{text}\": panel '{panel}' has no edge '{edge}'; its edges are {}", names[p].1.join(", ")))
    })?;
    Ok((p, e))
}

/// The stretch of an edge of `length` (m) that `span` (garment units) names.
pub fn side(key: &str, (panel, edge): (usize, usize), span: Option<[f64; 2]>, length: f64, metres: f64) -> Result<Side, GarmentError> {
    let (from, to) = match span {
        None => (0.0, length),
        Some([a, b]) => (a * metres, b * metres),
    };
    let slack = 1e-9 + 1e-6 * length;
    if !(from.is_finite() && to.is_finite() && 0.0 <= from + slack && from < to && to <= length + slack) {
        return Err(GarmentError::new(format!(
            "{key}_span = [{}, {}] must be an increasing stretch within the edge's length {:.4} (garment units)",
            from / metres,
            to / metres,
            length / metres
        )));
    }
    Ok(Side { panel, edge, from: from.max(0.0), to: to.min(length) })
}

/// Where each panel's edges are cut: seam stretches into the same number of equal parts
/// on both sides (`counts[s]` for seam s), everything else into parts of about
/// `edge_length`. `lengths[p][e]` is the length of edge e of panel p (m).
pub fn cuts(lengths: &[Vec<f64>], seams: &[(Side, Side)], counts: &[usize], edge_length: f64, names: &[(String, Vec<String>)]) -> Result<Vec<Vec<Cuts>>, GarmentError> {
    let parts = |length: f64| ((length / edge_length).round() as usize).max(1);
    // A gap between stretches, or a rest of an edge after its last stretch, shorter than
    // this is rounding in the pattern (a span written to a micrometre), not cloth: a vertex
    // there would make a triangle of no area.
    let tiny = 1e-3 * edge_length;
    let mut all = Vec::with_capacity(lengths.len());
    for (p, edges) in lengths.iter().enumerate() {
        let mut panel_cuts = Vec::with_capacity(edges.len());
        for (e, &length) in edges.iter().enumerate() {
            // The seam stretches on this edge, in order along it.
            let mut stretches: Vec<(f64, f64, usize, usize)> = seams
                .iter()
                .zip(counts)
                .enumerate()
                .flat_map(|(i, ((a, b), &n))| [(a, n, i), (b, n, i)])
                .filter(|(s, _, _)| s.panel == p && s.edge == e)
                .map(|(s, n, i)| (s.from, s.to, n, i))
                .collect();
            stretches.sort_by(|x, y| x.0.total_cmp(&y.0));
            let mut cut = vec![0.0];
            let mut at = 0.0;
            let mut last = None;
            for (from, to, n, i) in stretches {
                if let (true, Some(j)) = (from < at - 1e-9, last) {
                    let which = if i == j { format!("garment.seams[{i}] sews edge '{}' of panel '{}' to itself", names[p].1[e], names[p].0) } else {
                        format!("garment.seams[{}] and garment.seams[{}] overlap on edge '{}' of panel '{}'", i.min(j), i.max(j), names[p].1[e], names[p].0)
                    };
                    return Err(GarmentError::new(format!("{which}; give each side its own stretch with a_span / b_span")));
                }
                last = Some(i);
                if from > at + tiny {
                    cut.extend(even_cuts(at, from - at, parts(from - at)).into_iter().skip(1));
                }
                cut.extend(even_cuts(from, to - from, n).into_iter().skip(1));
                at = to;
            }
            if length > at + tiny {
                cut.extend(even_cuts(at, length - at, parts(length - at)).into_iter().skip(1));
            } else if let Some(last) = cut.last_mut() {
                *last = length;
            }
            panel_cuts.push(cut);
        }
        all.push(panel_cuts);
    }
    Ok(all)
}
