//! Where the bending stencils read rest positions: one plane for a flat specimen, or for a
//! cloth of panels a local chart around each edge, unfolded across seams from the
//! triangles' own rest shapes.
//!
//! ```text
//!    panel A frame        panel B frame          chart of edge e (A's frame)
//!      ____                 ____                   ____ ____
//!     |\  e|               |\   |                 |\  e|\   |
//!     | \  |  seam  +      | \  |       →         | \  | \  |   B's triangles turned and
//!     |__\_|               |__\_|                 |__\_|__\_|   moved onto the shared edge
//! ```
//!
//! A garment's panels are flat and its seams join edges of (nearly) equal length, so the
//! surface is flat in its rest metric away from seam ends: laying each neighbouring
//! triangle onto the edge it shares with one already laid reproduces, around any edge, the
//! flat neighbourhood a single cut would have. The bending fits then see the same rest
//! geometry across a seam as inside a panel, and a welded seam bends like cloth.

use super::sorted_edge;
use glam::DVec2;
use rustc_hash::FxHashMap;

/// A rigid motion of the plane: chart point = rotation · own point + offset.
#[derive(Debug, Clone, Copy)]
pub(super) struct Placement {
    /// (cos φ, sin φ) of the rotation.
    pub rotation: DVec2,
    pub offset: DVec2,
}

impl Placement {
    const IDENTITY: Self = Self { rotation: DVec2::X, offset: DVec2::ZERO };

    pub fn apply(&self, p: DVec2) -> DVec2 {
        self.rotation.rotate(p) + self.offset
    }

    /// A chart-frame gradient weight (a covector) in the triangle's own frame: Rᵀ c.
    pub fn in_own_frame(&self, c: DVec2) -> DVec2 {
        DVec2::new(self.rotation.x * c.x + self.rotation.y * c.y, -self.rotation.y * c.x + self.rotation.x * c.y)
    }

    /// A chart point in the triangle's own frame: Rᵀ (p − offset).
    pub fn point_to_own(&self, p: DVec2) -> DVec2 {
        self.in_own_frame(p - self.offset)
    }
}

/// The rest geometry of a cloth of panels, for unfolding charts.
pub(super) struct PanelCharts<'a> {
    pub triangles: &'a [[u32; 3]],
    /// Each triangle's corners in its own warp frame, m.
    pub corners: &'a [[DVec2; 3]],
    /// The triangles (and local edge index) on each edge.
    pub edge_owner: &'a std::collections::HashMap<[u32; 2], Vec<(usize, usize)>>,
    /// Triangles whose centroid lies farther than this from the edge's midpoint are not
    /// laid out, m: well beyond the three rings the fits grow to.
    pub reach: f64,
}

/// The chart around one edge: nearby vertices in the frame of the edge's first triangle,
/// and how each laid triangle's own frame sits in it.
pub(super) struct EdgeChart {
    pub points: FxHashMap<u32, DVec2>,
    pub placements: FxHashMap<usize, Placement>,
}

impl PanelCharts<'_> {
    /// Lays out the triangles around `edge` of triangle `start`, breadth first across
    /// shared edges, each by the rigid motion that puts its copy of the shared edge onto
    /// the laid one (their midpoints together, their directions aligned). A vertex keeps
    /// the place it was first given.
    pub fn unfold(&self, start: usize, edge: [u32; 2]) -> EdgeChart {
        let mut points = FxHashMap::default();
        let mut placements = FxHashMap::default();
        placements.insert(start, Placement::IDENTITY);
        for (v, p) in self.triangles[start].iter().zip(self.corners[start]) {
            points.insert(*v, p);
        }
        let midpoint = 0.5 * (points[&edge[0]] + points[&edge[1]]);
        let mut queue = std::collections::VecDeque::from([start]);
        while let Some(t) = queue.pop_front() {
            let laid = placements[&t];
            let tri = self.triangles[t];
            for k in 0..3 {
                let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                for &(u, _) in &self.edge_owner[&sorted_edge(tri[i], tri[j])] {
                    if placements.contains_key(&u) {
                        continue;
                    }
                    let placement = self.placement_across(u, (tri[i], laid.apply(self.corners[t][i])), (tri[j], laid.apply(self.corners[t][j])));
                    let centroid = placement.apply((self.corners[u][0] + self.corners[u][1] + self.corners[u][2]) / 3.0);
                    if centroid.distance(midpoint) > self.reach {
                        continue;
                    }
                    placements.insert(u, placement);
                    for (v, p) in self.triangles[u].iter().zip(self.corners[u]) {
                        points.entry(*v).or_insert_with(|| placement.apply(p));
                    }
                    queue.push_back(u);
                }
            }
        }
        EdgeChart { points, placements }
    }

    /// The placement of triangle `u` that lays its copy of the edge (a, b) onto the laid
    /// points `pa`, `pb`.
    fn placement_across(&self, u: usize, (a, pa): (u32, DVec2), (b, pb): (u32, DVec2)) -> Placement {
        let local = |v: u32| self.triangles[u].iter().position(|&w| w == v).expect("the shared edge's vertices are the triangle's");
        let (qa, qb) = (self.corners[u][local(a)], self.corners[u][local(b)]);
        let (laid, own) = ((pb - pa).normalize(), (qb - qa).normalize());
        // The rotation taking `own` to `laid`, as a unit complex number laid · conj(own).
        let rotation = DVec2::new(laid.x * own.x + laid.y * own.y, laid.y * own.x - laid.x * own.y);
        let offset = 0.5 * (pa + pb) - rotation.rotate(0.5 * (qa + qb));
        Placement { rotation, offset }
    }
}
