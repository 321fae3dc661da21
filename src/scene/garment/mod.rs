//! Garment scenes: the pattern built around its form, sewn by springs that grow until
//! every seam is closed, then welded into one surface that drapes on the form.
//!
//! ```text
//!   build: panels meshed and placed, the form as a mesh prop, the welded model made
//!          up front (so a pattern that cannot be welded is refused before any work)
//!   sew:   springs ½k·max(0, d − s(t)·d₀)², the slack s(t) = max(0, 1 − t/ramp), pull
//!          seam pairs together and attached edges onto the form on schedule, then
//!          stiffen while a seam is still held open; self-collision as the scene asks,
//!          less the pairs near a common seam (whose two sides must meet)
//!   weld:  once every pair is within `closed_share` of the contact thickness: pairs
//!          merged, the welded model takes over (membrane and bending across the seams),
//!          attached vertices pinned where they are, self-collision everywhere
//! ```

pub mod rig;

use crate::settings::SceneConfig;
use crate::scene::check::MAX_SEWING_STIFFNESS;
use super::{Scene, SceneError};
use crate::garment::{self, Garment, form};
use crate::sim::contact::{ContactModel, Prop, PropShape};
use crate::sim::model::PanelSurface;
use crate::sim::{Model, PhysicsOptions, State};
use glam::{DQuat, DVec2, DVec3};

/// Sewing in progress or done.
pub struct Sewing {
    /// The seams' final spring stiffness (N/m), its ramp (s) and the time by which the
    /// seams must be closed (s).
    stiffness: f64,
    ramp: f64,
    deadline: f64,
    /// A seam is closed when its pairs are this close, m.
    closed_gap: f64,
    /// Air damping while sewing, and the scene's from the weld on, 1/s.
    damping: (f64, f64),
    /// The welded cloth's model, built with the scene; taken at the weld.
    welded: Option<Model>,
    /// Vertices the pattern pins from the start (`garment.pinned`) and those pinned once
    /// the garment is sewn (attached ones), unsewn numbering: what the weld pins, and not a
    /// vertex the viewer's mouse happens to hold then.
    pinned: Vec<u32>,
    pin_after: Vec<u32>,
    /// Each seam's vertex pairs (unsewn numbering), and whether it has been open (a pair
    /// farther apart than `closed_gap`) from the start until the last step.
    seams: Vec<Vec<[u32; 2]>>,
    open: Vec<bool>,
    /// When the seams were welded, and the largest gap then, m.
    pub sewn_at: Option<f64>,
    pub gap_at_weld: Option<f64>,
}

impl Sewing {
    /// Whether the garment is sewn (welded).
    pub fn is_sewn(&self) -> bool {
        self.sewn_at.is_some()
    }

    /// Whether the sewing time has passed with a seam still open.
    pub fn failed(&self, time: f64) -> bool {
        !self.is_sewn() && time > self.deadline
    }
}

/// How a garment's sewing stands (`Scene::sewing_progress`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SewingProgress {
    /// When the seams were welded, s.
    pub sewn_at: Option<f64>,
    /// The largest gap still open between a seam's pairs, m (0 once sewn).
    pub open_gap: f64,
    /// The sewing time passed with a seam still open.
    pub failed: bool,
}

/// The parts `Scene::build_level` assembles for a garment.
pub struct Parts {
    pub model: Model,
    pub x: Vec<DVec3>,
    pub props: Vec<Prop>,
    pub rig: rig::GarmentRig,
    pub sewing: Sewing,
}

/// The dress form as a prop, and the height of its named levels (none for an OBJ body).
pub fn build_form(config: &SceneConfig) -> Result<(Prop, Option<form::Measurements>), SceneError> {
    let g = config.garment.as_ref().ok_or_else(|| SceneError::Setup("a garment scene needs a [garment] section".into()))?;
    let metres = g.units.metres();
    let axis = DVec3::new(g.form.axis[0] * metres, g.form.axis[1] * metres, 0.0);
    let measurements = g.form.measurements(g.units).map_err(|e| SceneError::Setup(e.to_string()))?;
    let shape = match (&measurements, &g.form.obj) {
        (Some(m), _) => {
            let (vertices, triangles) = form::form_mesh(m);
            PropShape::Mesh { vertices, triangles }
        }
        (None, Some(file)) => {
            let scale = g.form.scale.unwrap_or(1.0);
            let (vertices, triangles) = super::props::load_obj(file, config.base_dir.as_deref(), scale).map_err(|e| SceneError::Setup(format!("garment.form.obj: {e}")))?;
            PropShape::Mesh { vertices: vertices.into_iter().map(|v| v * scale).collect(), triangles }
        }
        (None, None) => return Err(SceneError::Setup("garment.form: give size, measurements or obj".into())),
    };
    let prop = Prop::new("form", shape, axis, DQuat::IDENTITY).map_err(|e| SceneError::Setup(e.to_string()))?;
    Ok((prop, measurements))
}

/// Builds a garment scene's model, start, props, rig and sewing, around the scene's
/// `props` (the form goes first); `meshed` is the pattern the checks meshed, where it is
/// at this level's edge length (None: meshed here).
pub fn build(config: &SceneConfig, fabric: &crate::sim::Fabric, options: PhysicsOptions, mut props: Vec<Prop>, meshed: Option<Garment>) -> Result<Parts, SceneError> {
    let g = config.garment.as_ref().ok_or_else(|| SceneError::Setup("a garment scene needs a [garment] section".into()))?;
    let metres = g.units.metres();
    let (form, measurements) = build_form(config)?;
    let axis = DVec2::new(g.form.axis[0], g.form.axis[1]) * metres;
    let level = |name: &str| measurements.as_ref()?.level(name);
    let garment = match meshed {
        Some(garment) => garment,
        None => garment::build(g, config.mesh.edge_length, axis, &level).map_err(|e| SceneError::Setup(e.to_string()))?,
    };
    let thickness = config.contact.thickness;
    check_outside(&garment, &form, thickness)?;
    let pairs = garment.seam_pairs();
    let mut model = Model::from_panels(&garment.surface, &pairs, fabric, options)?;
    let x = garment.positions.clone();
    let (welded_surface, weld_map) = weld_surface(&garment.surface, &pairs);
    let closed_gap = g.closed_share * thickness;
    let open = still_open(&garment.seams, &vec![true; garment.seams.len()], &x, closed_gap);
    model.sewing.bands = crate::sim::model::seam_bands(&garment.seams, &open, &model.triangles, x.len());
    model.sewing.welded = weld_map;
    if config.contact.self_collision {
        check_uncrossed(&garment, &model)?;
        check_apart(&garment, &model, config.contact.self_thickness_for(model.mean_edge_length))?;
    }
    for &v in &garment.pinned {
        model.pin(v, x[v as usize]);
    }
    model.sewing.anchors = anchors(&garment, &form, axis, thickness);
    model.sewing.start(&x);
    model.sewing.slack = 1.0;
    let mut welded = Model::from_panels(&welded_surface, &[], fabric, options)?;
    props.insert(0, form);
    let settings = config.contact;
    welded.contact = Some(ContactModel::new(props.clone(), settings).map_err(SceneError::Setup)?);
    model.contact = Some(ContactModel::new(props.clone(), settings).map_err(SceneError::Setup)?);
    let pin_after: Vec<u32> = model.sewing.anchors.iter().map(|a| a.0).collect();
    let sewing = Sewing {
        stiffness: g.sewing_stiffness,
        ramp: g.sewing_ramp,
        deadline: g.sewing_time,
        closed_gap,
        damping: (g.sewing_damping, config.solver.damping),
        welded: Some(welded),
        pinned: garment.pinned.clone(),
        pin_after,
        seams: garment.seams.clone(),
        open,
        sewn_at: None,
        gap_at_weld: None,
    };
    let rig = rig::GarmentRig::new(&garment, &props[0], measurements.as_ref(), config);
    Ok(Parts { model, x, props, rig, sewing })
}

/// How long the sewing springs take to double their stiffness once the sewing's
/// schedule has run out with a seam still open, s.
const STIFFEN_DOUBLING: f64 = 0.05;

/// Which seams are open at `x` (a pair farther apart than `closed_gap`) among those that
/// have been (`was_open`): a seam that has closed counts as closed from then on.
fn still_open(seams: &[Vec<[u32; 2]>], was_open: &[bool], x: &[DVec3], closed_gap: f64) -> Vec<bool> {
    seams.iter().zip(was_open).map(|(seam, &open)| open && seam.iter().any(|&[a, b]| x[a as usize].distance(x[b as usize]) > closed_gap)).collect()
}

/// Refuses a panel that starts inside the form (or within its contact layer).
fn check_outside(garment: &Garment, form: &Prop, thickness: f64) -> Result<(), SceneError> {
    for (p, (name, _)) in garment.names.iter().enumerate() {
        let end = garment.offsets.get(p + 1).copied().unwrap_or(garment.positions.len() as u32);
        for v in garment.offsets[p]..end {
            let x = garment.positions[v as usize];
            if form.surface_point(x).distance < thickness {
                return Err(SceneError::Setup(format!(
                    "garment.panels '{name}': starts inside the form (its point at {:.3?} m is {:.1} mm from the form's surface, within the {:.1} mm contact layer); \
                     place it farther out (placement.distance) or higher",
                    x.to_array(),
                    1e3 * form.surface_point(x).distance,
                    1e3 * thickness
                )));
            }
        }
    }
    Ok(())
}

/// Refuses panels placed through each other (or a panel through itself), naming them:
/// self-collision keeps cloth from crossing, so it could never part them, and the garment
/// would end tangled.
fn check_uncrossed(garment: &Garment, model: &Model) -> Result<(), SceneError> {
    let panel_of = |v: u32| garment.offsets.partition_point(|&o| o <= v) - 1;
    let mut pairs = std::collections::BTreeMap::<(usize, usize), usize>::new();
    for (e, t) in crate::sim::contact::self_intersections(&garment.positions, &model.triangles, &model.edges) {
        let (a, b) = (panel_of(model.edges[e][0]), panel_of(model.triangles[t][0]));
        *pairs.entry((a.min(b), a.max(b))).or_default() += 1;
    }
    let Some((&(a, b), &n)) = pairs.iter().next() else { return Ok(()) };
    let name = |p: usize| &garment.names[p].0;
    let which = if a == b { format!("garment.panels '{}' starts through itself", name(a)) } else { format!("garment.panels '{}' and '{}' start through each other", name(a), name(b)) };
    let more = match pairs.len() - 1 {
        0 => String::new(),
        m => format!(" (and {m} more pairs of panels)"),
    };
    Err(SceneError::Setup(format!(
        "{which}: {n} edges cross as placed{more}; self-collision keeps cloth from crossing, so it could never part them. \
         Place them apart (placement.angle_deg, distance or height)"
    )))
}

/// How much farther apart on the flat pattern than self-collision's layer two points of one
/// panel must be cut for their closeness in space to be a fold.
const FOLD_SPAN: f64 = 3.0;

/// Refuses panels placed within the layer self-collision keeps between cloth layers
/// (`reach`, m) of each other, or a panel folded onto itself, leaving out the pairs that
/// the sewing must bring together: the layer's penalty would throw them apart in the first
/// step, and the sewing then pulls one through the other (a gore placed 1 mm outside
/// another ended its first second with 86 crossings, and failed Newton's tolerance with
/// self-collision on).
fn check_apart(garment: &Garment, model: &Model, reach: f64) -> Result<(), SceneError> {
    let panel_of = |v: u32| garment.offsets.partition_point(|&o| o <= v) - 1;
    // Within one panel, a pair is folded only where the cloth between them is longer than
    // the gap: neighbours on the flat pattern (small triangles along a hem drawn as many
    // short segments) are close because they are cut close.
    let flat = |p: DVec2| DVec3::new(p.x, p.y, 0.0);
    let cut_apart = |v: u32, t: u32| {
        let pattern = &garment.surface.pattern;
        let c = model.triangles[t as usize].map(|i| flat(pattern[i as usize]));
        let p = flat(pattern[v as usize]);
        let (closest, _) = crate::sim::contact::geometry::closest_point_triangle(p, c[0], c[1], c[2]);
        closest.distance(p) > FOLD_SPAN * reach
    };
    let mut close = crate::sim::contact::pairs_within(&garment.positions, model.cloth(), reach);
    close.retain(|&(v, t, _)| panel_of(v) != panel_of(model.triangles[t as usize][0]) || cut_apart(v, t));
    let Some(&(v, t, gap)) = close.iter().min_by(|a, b| a.2.total_cmp(&b.2)) else { return Ok(()) };
    let (a, b) = (panel_of(v), panel_of(model.triangles[t as usize][0]));
    let (a, b) = (a.min(b), a.max(b));
    let name = |p: usize| &garment.names[p].0;
    let which = if a == b { format!("garment.panels '{}' starts folded onto itself", name(a)) } else { format!("garment.panels '{}' and '{}' start", name(a), name(b)) };
    Err(SceneError::Setup(format!(
        "{which} {:.1} mm apart at {:.3?} m ({} points closer than {:.1} mm, the layer self-collision keeps between cloth layers); \
         the sewing would pull one through the other. Place them apart (placement.angle_deg, distance or height)",
        1e3 * gap,
        garment.positions[v as usize].to_array(),
        close.len(),
        1e3 * reach
    )))
}

/// The form's horizontal section at height `z`: `count` points found by rays from outside
/// towards the axis, each pushed out by `offset` (m).
pub fn section(form: &Prop, axis: DVec2, z: f64, count: usize, offset: f64) -> Vec<DVec3> {
    (0..count)
        .filter_map(|k| {
            let dir = DVec2::from_angle(std::f64::consts::TAU * k as f64 / count as f64);
            let centre = DVec3::new(axis.x, axis.y, z);
            let outside = centre + 3.0 * DVec3::new(dir.x, dir.y, 0.0);
            form.segment_entry(outside, centre).map(|hit| hit.point + offset * DVec3::new(dir.x, dir.y, 0.0))
        })
        .collect()
}

/// Where each attached vertex is pulled: onto the form's section at its height, pushed out
/// by 1.5 contact thicknesses. The edges attached at one height share that section in
/// proportion to their lengths, each centred where it starts and running the way it runs
/// around the axis, so that a waist of the form's girth goes on without stretch.
fn anchors(garment: &Garment, form: &Prop, axis: DVec2, thickness: f64) -> Vec<(u32, DVec3)> {
    let mut heights: Vec<f64> = garment.attached_edges.iter().map(|&(_, z)| z).collect();
    heights.sort_by(f64::total_cmp);
    heights.dedup();
    let angle_of = |v: u32| {
        let p = garment.positions[v as usize];
        (p.y - axis.y).atan2(p.x - axis.x)
    };
    let mut out = Vec::new();
    for z in heights {
        let ring = section(form, axis, z, 720, 1.5 * thickness);
        if ring.len() < 3 {
            continue;
        }
        let arc: Vec<f64> = std::iter::once(0.0).chain(ring.iter().zip(ring.iter().cycle().skip(1)).scan(0.0, |s, (a, b)| {
            *s += a.distance(*b);
            Some(*s)
        })).collect();
        let girth = *arc.last().unwrap();
        let at = |s: f64| {
            let s = s.rem_euclid(girth);
            let i = arc.partition_point(|&a| a <= s).clamp(1, ring.len());
            let t = (s - arc[i - 1]) / (arc[i] - arc[i - 1]).max(1e-12);
            ring[i - 1].lerp(ring[i % ring.len()], t)
        };
        // Arc length on the section at the ray nearest an angle.
        let arc_at = |angle: f64| arc[((angle.rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU * ring.len() as f64).round() as usize) % ring.len()];
        let edges: Vec<&Vec<u32>> = garment.attached_edges.iter().filter(|(_, h)| *h == z).map(|(e, _)| e).collect();
        let rest = |e: &[u32]| -> Vec<f64> {
            std::iter::once(0.0).chain(e.windows(2).scan(0.0, |s, w| {
                *s += garment.surface.pattern[w[0] as usize].distance(garment.surface.pattern[w[1] as usize]);
                Some(*s)
            })).collect()
        };
        let total: f64 = edges.iter().map(|e| *rest(e).last().unwrap()).sum();
        for e in edges {
            let s = rest(e);
            let length = *s.last().unwrap();
            let mid = e[s.partition_point(|&a| a < 0.5 * length).min(e.len() - 1)];
            let turn = (angle_of(*e.last().unwrap()) - angle_of(e[0]) + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
            let centre = arc_at(angle_of(mid));
            for (v, si) in e.iter().zip(&s) {
                out.push((*v, at(centre + turn.signum() * (si - 0.5 * length) * girth / total)));
            }
        }
    }
    out
}

/// The cloth with every seam pair merged: the welded surface and each old vertex's new index.
fn weld_surface(surface: &PanelSurface, pairs: &[[u32; 2]]) -> (PanelSurface, Vec<u32>) {
    let n = surface.pattern.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn root(parent: &mut [u32], v: u32) -> u32 {
        let mut r = v;
        while parent[r as usize] != r {
            r = parent[r as usize];
        }
        let mut v = v;
        while parent[v as usize] != r {
            let next = parent[v as usize];
            parent[v as usize] = r;
            v = next;
        }
        r
    }
    for &[a, b] in pairs {
        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
        if ra != rb {
            parent[ra.max(rb) as usize] = ra.min(rb);
        }
    }
    let mut new_index = vec![u32::MAX; n];
    let mut map = vec![0u32; n];
    let (mut pattern, mut texture) = (Vec::new(), Vec::new());
    for v in 0..n as u32 {
        let r = root(&mut parent, v) as usize;
        if new_index[r] == u32::MAX {
            new_index[r] = pattern.len() as u32;
            pattern.push(surface.pattern[r]);
            texture.push(surface.texture[r]);
        }
        map[v as usize] = new_index[r];
    }
    let triangles = surface.triangles.iter().map(|t| t.map(|v| map[v as usize])).collect();
    (PanelSurface { triangles, corners: surface.corners.clone(), pattern, texture }, map)
}

impl Scene {
    /// Before a step of a garment still being sewn: the springs' slack and stiffness at
    /// the step's end time.
    pub(super) fn sew_before_step(&mut self) {
        let Some(sewing) = &mut self.garment else { return };
        if sewing.is_sewn() {
            return;
        }
        // Self-collision leaves out the pairs near a seam while the seam is open, from the
        // start until it first closes. A seam closed at the start, or since, keeps its
        // sides apart as the welded cloth will, even if the sewing of others pulls it open
        // again: GarmentCode's shirt starts with its centre front closed, the other seams
        // drew it 17 mm open, and its two fronts, left out there, folded through each other
        // in 20 places.
        let x = &self.state.x;
        let open = still_open(&sewing.seams, &sewing.open, x, sewing.closed_gap);
        if open != sewing.open {
            self.model.sewing.bands = crate::sim::model::seam_bands(&sewing.seams, &open, &self.model.triangles, x.len());
            sewing.open = open;
        }
        let t = self.state.time + self.integrator.dt;
        self.model.sewing.slack = (1.0 - t / sewing.ramp).max(0.0);
        // Past its schedule a seam held open by a load (a waist pulled round the form)
        // is drawn tighter: the springs stiffen twofold every STIFFEN_DOUBLING seconds
        // until it closes, up to the largest stiffness a scene may ask for.
        let late = ((t - sewing.ramp) / STIFFEN_DOUBLING).max(0.0);
        self.model.sewing.stiffness = (sewing.stiffness * late.exp2()).min(MAX_SEWING_STIFFNESS.max(sewing.stiffness));
        self.model.options.damping = sewing.damping.0;
    }

    /// How the garment's sewing stands, for the viewer: when it was welded, or the largest
    /// gap still open between the seams' pairs (m) and whether its sewing time has passed.
    pub fn sewing_progress(&self) -> Option<SewingProgress> {
        let sewing = self.garment.as_ref()?;
        Some(SewingProgress {
            sewn_at: sewing.sewn_at,
            open_gap: if sewing.is_sewn() { 0.0 } else { self.model.sewing.largest_gap(&self.state.x) },
            failed: sewing.failed(self.state.time),
        })
    }

    /// Takes `earlier`'s sewn garment into this garment scene, just built and not yet
    /// stepped, where both cut the very same mesh (another fabric, other grains, the other
    /// solver path): the garment re-drapes from where it hangs instead of being sewn again
    /// from flat panels. This scene's welded cloth (its own fabric and grains) takes the
    /// earlier cloth's positions, velocities and clock, and the pins the weld sets. Returns
    /// whether it did; where the pattern changed, the new scene sews from the start.
    pub fn continue_sewn(&mut self, earlier: &Scene) -> bool {
        let (Some(sewing), Some(before)) = (&mut self.garment, &earlier.garment) else { return false };
        let same_mesh = sewing.welded.as_ref().is_some_and(|w| w.triangles == earlier.model.triangles && w.rest == earlier.model.rest);
        if !before.is_sewn() || sewing.is_sewn() || self.state.steps > 0 || !same_mesh {
            return false;
        }
        let mut model = sewing.welded.take().expect("checked above");
        let weld_map = &self.model.sewing.welded;
        for &v in sewing.pinned.iter().chain(&sewing.pin_after) {
            let w = weld_map[v as usize];
            model.pin(w, earlier.state.x[w as usize]);
        }
        model.options = self.model.options;
        model.options.damping = sewing.damping.1;
        let mut state = State::at_rest(earlier.state.x.clone());
        state.v = earlier.state.v.clone();
        state.time = earlier.state.time;
        state.steps = earlier.state.steps;
        (sewing.sewn_at, sewing.gap_at_weld) = (before.sewn_at, before.gap_at_weld);
        if let (Some(rig), Some(at), Some(gap)) = (self.rig.as_any_mut().downcast_mut::<rig::GarmentRig>(), before.sewn_at, before.gap_at_weld) {
            rig.welded(weld_map, at, gap);
        }
        // The same mesh keeps its version (buffers and drags stay valid) unless its texture
        // turned with new grains; then a merge onto itself keeps the vertices' indices.
        self.topology = if model.texture_space().0 == earlier.topology.texture.as_slice() {
            std::sync::Arc::clone(&earlier.topology)
        } else {
            let identity = (0..model.vertex_count() as u32).collect();
            std::sync::Arc::new(super::Topology::merged(&model, &earlier.topology, identity))
        };
        self.integrator = {
            let mut integrator = self.level_solver.integrator();
            integrator.contact_stats = earlier.integrator.contact_stats;
            integrator
        };
        self.model = model;
        self.state = state;
        true
    }

    /// After a step: welds the garment once every seam and attachment is closed.
    pub(super) fn sew_after_step(&mut self) {
        let Some(sewing) = &mut self.garment else { return };
        if sewing.is_sewn() {
            return;
        }
        let x = &self.state.x;
        // The seams decide: an attached vertex whose anchor disagrees with its seam partner's
        // is pinned where the two settle.
        let gap = self.model.sewing.largest_gap(x);
        if gap > sewing.closed_gap {
            return;
        }
        let mut model = sewing.welded.take().expect("the welded model waits until the weld");
        // For each vertex of the unsewn cloth, its vertex in the welded one.
        let weld_map = &self.model.sewing.welded;
        let n = model.vertex_count();
        let (mut mass, mut position, mut velocity) = (vec![0.0; n], vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
        for (v, &w) in weld_map.iter().enumerate() {
            let m = self.model.mass[v];
            mass[w as usize] += m;
            position[w as usize] += m * x[v];
            velocity[w as usize] += m * self.state.v[v];
        }
        for w in 0..n {
            position[w] /= mass[w];
            velocity[w] /= mass[w];
        }
        for &v in sewing.pinned.iter().chain(&sewing.pin_after) {
            let w = weld_map[v as usize];
            model.pin(w, position[w as usize]);
        }
        model.options = self.model.options;
        model.options.damping = sewing.damping.1;
        let mut state = State::at_rest(position);
        state.v = velocity;
        state.time = self.state.time;
        state.steps = self.state.steps;
        let mut integrator = self.level_solver.integrator();
        integrator.contact_stats = self.integrator.contact_stats;
        sewing.sewn_at = Some(self.state.time);
        sewing.gap_at_weld = Some(gap);
        if let Some(rig) = self.rig.as_any_mut().downcast_mut::<rig::GarmentRig>() {
            rig.welded(weld_map, self.state.time, gap);
        }
        self.topology = std::sync::Arc::new(super::Topology::merged(&model, &self.topology, weld_map.clone()));
        self.model = model;
        self.state = state;
        self.integrator = integrator;
    }
}
