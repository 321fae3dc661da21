//! The cloth's mesh as everything downstream of the solver sees it: the renderer, the
//! colour fields, picking and dragging, the exporters. A run may change its mesh: a garment's
//! seams weld (fewer vertices, the same triangles renumbered), the fast path moves to a finer
//! level, the viewer rebuilds the scene for a new fabric or a recut. Each mesh gets a
//! [`Topology`] with a version no other mesh in the process shares, so a consumer compares the
//! version instead of guessing from a count (a weld keeps the triangle count).

use crate::sim::Model;
use glam::{DVec2, DVec3};
use std::sync::atomic::{AtomicU64, Ordering};

/// Versions are unique in the process, so meshes of different scenes never compare equal.
static NEXT_VERSION: AtomicU64 = AtomicU64::new(1);

/// One mesh of the cloth: what stays fixed until the mesh changes.
#[derive(Debug, Clone, PartialEq)]
pub struct Topology {
    /// Changes whenever the mesh does; never reused.
    pub version: u64,
    /// Vertices the positions of this mesh hold.
    pub vertex_count: usize,
    /// Triangles (counter-clockwise in the rest plane), indices below `vertex_count`.
    pub triangles: Vec<[u32; 3]>,
    /// Texture coordinates, m, one per vertex: the rest plane, or a garment's texture space
    /// (each panel in its warp frame); `sim::Model::texture_space`.
    pub texture: Vec<DVec2>,
    /// The warp's angle from the texture coordinates' x axis, radians.
    pub warp_angle: f64,
    /// Where this mesh came from when it replaced another by merging vertices (a weld): the
    /// earlier mesh's version and, per earlier vertex, its vertex here. `None` when the
    /// meshes are unrelated (a finer level, a rebuilt scene).
    pub merged_from: Option<(u64, Vec<u32>)>,
}

impl Topology {
    /// The mesh of `model`, under a new version.
    pub fn of(model: &Model) -> Self {
        let (texture, warp_angle) = model.texture_space();
        Self {
            version: NEXT_VERSION.fetch_add(1, Ordering::Relaxed),
            vertex_count: model.vertex_count(),
            triangles: model.triangles.clone(),
            texture: texture.to_vec(),
            warp_angle,
            merged_from: None,
        }
    }

    /// The mesh of `model`, made from `earlier` by merging each earlier vertex `v` into
    /// `map[v]`.
    pub fn merged(model: &Model, earlier: &Topology, map: Vec<u32>) -> Self {
        Self { merged_from: Some((earlier.version, map)), ..Self::of(model) }
    }

    /// Whether `positions` belong to this mesh: one point per vertex.
    pub fn fits(&self, positions: &[DVec3]) -> bool {
        positions.len() == self.vertex_count
    }

    /// Whether vertex indices of the mesh of version `from` mean something here: this mesh
    /// itself, or the one it was merged from.
    pub fn follows(&self, from: u64) -> bool {
        from == self.version || self.merged_from.as_ref().is_some_and(|(earlier, _)| *earlier == from)
    }

    /// Where vertex `vertex` of the mesh of version `from` is on this one: itself on the same
    /// mesh, its merged vertex across a weld, `None` across unrelated meshes.
    pub fn carry_vertex(&self, from: u64, vertex: u32) -> Option<u32> {
        if from == self.version {
            return (vertex as usize).lt(&self.vertex_count).then_some(vertex);
        }
        match &self.merged_from {
            Some((earlier, map)) if *earlier == from => map.get(vertex as usize).copied(),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn topology(vertex_count: usize, merged_from: Option<(u64, Vec<u32>)>) -> Topology {
        Topology {
            version: NEXT_VERSION.fetch_add(1, Ordering::Relaxed),
            vertex_count,
            triangles: Vec::new(),
            texture: vec![DVec2::ZERO; vertex_count],
            warp_angle: 0.0,
            merged_from,
        }
    }

    #[test]
    fn a_vertex_is_carried_across_a_weld_and_not_across_unrelated_meshes() {
        let open = topology(4, None);
        // Vertices 1 and 3 of the open mesh are sewn into one.
        let welded = topology(3, Some((open.version, vec![0, 1, 2, 1])));
        assert_ne!(open.version, welded.version);
        assert_eq!(welded.carry_vertex(open.version, 3), Some(1));
        assert_eq!(welded.carry_vertex(open.version, 9), None, "no such vertex");
        assert_eq!(welded.carry_vertex(welded.version, 2), Some(2));
        assert_eq!(welded.carry_vertex(welded.version, 3), None, "past the welded mesh");
        let finer = topology(10, None);
        assert_eq!(finer.carry_vertex(welded.version, 0), None);
        assert!(welded.follows(open.version) && welded.follows(welded.version) && !finer.follows(welded.version));
    }
}
