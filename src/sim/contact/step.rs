//! The contacts of one step as energies in the implicit solve: their potential, gradient,
//! Hessian and couplings, and the step limits that keep cloth–cloth pairs from meeting.

use super::{SelfPair, StepContacts, closing_bound};
use super::geometry::{closest_point_triangle, closest_points_segments, edge_edge_ccd, vertex_triangle_ccd};
use crate::sim::linalg::{BlockCsr, Coupling};
use glam::{DMat3, DVec3};

impl StepContacts {
    pub fn is_empty(&self) -> bool {
        self.planes.is_empty() && self.pairs.is_empty()
    }

    pub fn plane_count(&self) -> usize {
        self.planes.len()
    }

    pub fn pair_count(&self) -> usize {
        self.pairs.len()
    }

    /// After the step to `y`: where each vertex in contact with a prop sticks from for the
    /// next step (None: not in contact). A vertex within ε of its stick point keeps it; one
    /// beyond slides, and its stick point is dragged along, ε behind it along the slip, so
    /// that friction decays from static to kinetic as the smoothed law does.
    ///
    /// Smoothed friction is viscous below the slip threshold ε: measured from each step's
    /// start, a sticking vertex under a sideways pull F slides on at slip_speed·F/(μN)
    /// for ever, and a skirt resting on its form's hips or a tablecloth's middle creeps at
    /// up to the slip speed, which is the bundled settle speed. Measured from where it
    /// stuck, the slip grows only until friction balances the pull (εF/(μN) < ε) and the
    /// vertex then stays: static friction holds, as Coulomb's does.
    pub fn stuck_after(&self, y: &[DVec3], stuck: &mut Vec<Option<DVec3>>) {
        stuck.clear();
        stuck.resize(y.len(), None);
        for c in &self.planes {
            if c.normal_force <= 0.0 {
                continue;
            }
            let i = c.vertex as usize;
            let t = c.slip(y[i]);
            let slip = t.length();
            stuck[i] = Some(if slip <= self.slip { c.stick } else { y[i] - self.slip / slip * t });
        }
    }

    /// The vertices that end the step at `y` sticking to a prop with their friction force
    /// within `margin` of μ_s times the normal force (their slip within `margin` of the
    /// slip threshold), with that prop's normal.
    pub fn sticking(&self, y: &[DVec3], margin: f64) -> Vec<(u32, DVec3)> {
        self.planes
            .iter()
            .filter(|c| c.normal_force > 0.0 && c.slip(y[c.vertex as usize]).length() <= margin * self.slip)
            .map(|c| (c.vertex, c.normal))
            .collect()
    }

    /// Friction dissipation function F(s) and F'(s) of the tangential slip s over the step.
    fn friction(&self, s: f64) -> (f64, f64) {
        let (e, ms, mk) = (self.slip, self.mu_static, self.mu_kinetic);
        if s <= e {
            (ms * s * s / (2.0 * e), ms * s / e)
        } else {
            let decay = (-(s - e) / e).exp();
            (ms * e / 2.0 + mk * (s - e) + (ms - mk) * e * (1.0 - decay), mk + (ms - mk) * decay)
        }
    }

    /// Distance of a pair at `y`, the unit direction from the second part to the first, and
    /// the weights c with d = n·Σ c_j y_j (to first order).
    fn self_distance(&self, pair: &SelfPair, y: &[DVec3]) -> (f64, DVec3, [f64; 4]) {
        let p = pair.vertices.map(|i| y[i as usize]);
        let (offset, weights) = if pair.edge_edge {
            let (s, t) = closest_points_segments(p[0], p[1], p[2], p[3]);
            (p[0].lerp(p[1], s) - p[2].lerp(p[3], t), [1.0 - s, s, t - 1.0, -t])
        } else {
            let (q, w) = closest_point_triangle(p[0], p[1], p[2], p[3]);
            (p[0] - q, [1.0, -w[0], -w[1], -w[2]])
        };
        let d = offset.length();
        (d, if d > 1e-15 { offset / d } else { DVec3::Z }, weights)
    }

    /// Contact energy plus friction dissipation at positions `y` (the slip measured from
    /// each contact's stick point, `PlaneContact::stick`).
    pub fn energy(&self, y: &[DVec3]) -> f64 {
        let mut e = 0.0;
        for c in &self.planes {
            let i = c.vertex as usize;
            e += c.penalty(y[i], self.thickness).0;
            if c.normal_force > 0.0 {
                let slip = c.slip(y[i]).length();
                e += c.normal_force * self.friction(slip).0;
            }
        }
        for p in &self.pairs {
            let (d, _, _) = self.self_distance(p, y);
            if d < self.self_thickness {
                e += 0.5 * p.stiffness * (self.self_thickness - d).powi(2);
            }
        }
        e
    }

    /// Adds ∇(energy) to `g` and returns the energy: [`Self::energy`] and
    /// [`Self::add_gradient`] from one pass.
    pub fn energy_and_gradient(&self, y: &[DVec3], g: &mut [DVec3], fixed: &[bool]) -> f64 {
        let mut e = 0.0;
        for c in &self.planes {
            let i = c.vertex as usize;
            let (energy, force, _) = c.penalty(y[i], self.thickness);
            e += energy;
            g[i] -= force * c.normal;
            if c.normal_force > 0.0 {
                let t = c.slip(y[i]);
                let slip = t.length();
                let (value, slope) = self.friction(slip);
                e += c.normal_force * value;
                if slip > 0.0 {
                    g[i] += c.normal_force * slope * t / slip;
                }
            }
        }
        for p in &self.pairs {
            let (d, n, w) = self.self_distance(p, y);
            if d < self.self_thickness {
                let f = p.stiffness * (self.self_thickness - d);
                e += 0.5 * p.stiffness * (self.self_thickness - d).powi(2);
                for (&j, &weight) in p.vertices.iter().zip(&w) {
                    if !fixed[j as usize] {
                        g[j as usize] -= f * weight * n;
                    }
                }
            }
        }
        e
    }

    /// Adds ∇(energy) to `g`.
    pub fn add_gradient(&self, y: &[DVec3], g: &mut [DVec3], fixed: &[bool]) {
        for c in &self.planes {
            let i = c.vertex as usize;
            g[i] -= c.penalty(y[i], self.thickness).1 * c.normal;
            if c.normal_force > 0.0 {
                let t = c.slip(y[i]);
                let slip = t.length();
                if slip > 0.0 {
                    g[i] += c.normal_force * self.friction(slip).1 * t / slip;
                }
            }
        }
        for p in &self.pairs {
            let (d, n, w) = self.self_distance(p, y);
            if d < self.self_thickness {
                let f = p.stiffness * (self.self_thickness - d);
                for (&j, &weight) in p.vertices.iter().zip(&w) {
                    if !fixed[j as usize] {
                        g[j as usize] -= f * weight * n;
                    }
                }
            }
        }
    }

    /// Adds a positive semi-definite approximation of the energy's Hessian to the diagonal
    /// blocks of `k`; the cloth–cloth pairs' off-diagonal parts come from
    /// [`StepContacts::couplings`]. Both are Gauss–Newton (the normal's rotation is left
    /// out), which keeps the system positive definite.
    pub fn add_hessian(&self, y: &[DVec3], k: &mut BlockCsr) {
        for c in &self.planes {
            let i = c.vertex as usize;
            let mut block = c.penalty(y[i], self.thickness).2 * outer(c.normal, c.normal);
            if c.normal_force > 0.0 {
                // λF(s) of the slip s = |u_T|: curvature λF'(s)/s across the slip and λF''(s)
                // along it. Sticking (s ≤ ε), F is quadratic and both are μ_s/ε. Sliding,
                // F'' < 0 as μ decays to μ_k; 0 is used there. λF'(s)/s along the slip would
                // be up to μ_s/ε·λ, many times a resting vertex's inertia at a small slip
                // threshold, and with it Newton creeps along a sliding vertex's path.
                let t = c.slip(y[i]);
                let slip = t.length();
                let tangent = DMat3::IDENTITY - outer(c.normal, c.normal);
                let (_, dfriction) = self.friction(slip.max(self.slip));
                block += tangent * (c.normal_force * dfriction / slip.max(self.slip));
                if slip > self.slip {
                    let along = t / slip;
                    block -= outer(along, along) * (c.normal_force * dfriction / slip);
                }
            }
            let slot = k.diagonal_slot(i as u32);
            k.values[slot] += block;
        }
        for p in &self.pairs {
            let (d, n, w) = self.self_distance(p, y);
            if d < self.self_thickness {
                let nn = outer(n, n) * p.stiffness;
                for (&j, &weight) in p.vertices.iter().zip(&w) {
                    let slot = k.diagonal_slot(j);
                    k.values[slot] += nn * (weight * weight);
                }
            }
        }
    }
}

impl StepContacts {
    /// Adds to each vertex's entry of `diagonal` the stiffness its contacts have at `y` in
    /// their stiffest direction (the penalty's k where the vertex is inside a prop's layer,
    /// friction's curvature across the slip λF'(s)/s, the cloth–cloth pairs' k w²), as an
    /// isotropic term: the quasi-Newton step's matrix takes contact in that form.
    pub fn add_isotropic_stiffness(&self, y: &[DVec3], diagonal: &mut [f64]) {
        for c in &self.planes {
            let i = c.vertex as usize;
            let mut k = c.penalty(y[i], self.thickness).2;
            if c.normal_force > 0.0 {
                let slip = c.slip(y[i]).length().max(self.slip);
                k = k.max(c.normal_force * self.friction(slip).1 / slip);
            }
            diagonal[i] += k;
        }
        for p in &self.pairs {
            let (d, _, w) = self.self_distance(p, y);
            if d < self.self_thickness {
                for (&j, &weight) in p.vertices.iter().zip(&w) {
                    diagonal[j as usize] += p.stiffness * weight * weight;
                }
            }
        }
    }
}

impl StepContacts {
    /// Makes prop contact inelastic: a vertex still inside its contact layer at the end of
    /// the step keeps no velocity away from the prop. The penalty is a spring, and BDF2,
    /// which hardly damps, would otherwise give back its energy as a bounce (a dropped
    /// cloth would jump back up nearly to its height); cloth does not bounce.
    /// Returns the vertices whose velocity changed.
    pub fn absorb_rebound(&self, y: &[DVec3], v: &mut [DVec3]) -> Vec<u32> {
        let mut changed = Vec::new();
        for c in &self.planes {
            let i = c.vertex as usize;
            let outward = v[i].dot(c.normal);
            if outward > 0.0 && self.thickness - c.normal.dot(y[i] - c.point) > 0.0 {
                v[i] -= outward * c.normal;
                changed.push(c.vertex);
            }
        }
        changed
    }

    /// Largest fraction of the Newton direction `d` from `y` along which no cloth–cloth
    /// pair can meet (additive CCD, Li et al. 2021): a pair at distance g whose vertices move
    /// at most |d_p| + max|d_j| cannot close that gap over a step shorter than g divided by it.
    /// Capping each line search there keeps every Newton iterate free of crossings, so the
    /// solve cannot carry a vertex around a triangle's edge to the far side.
    pub fn max_step(&self, y: &[DVec3], d: &[DVec3]) -> f64 {
        self.step_limit(y, d).min(1.0)
    }

    /// The multiple of `d` (any size) from `y` up to which no cloth–cloth pair can meet; see
    /// [`Self::max_step`].
    pub fn step_limit(&self, y: &[DVec3], d: &[DVec3]) -> f64 {
        let mut alpha = f64::INFINITY;
        for p in &self.pairs {
            let bound = closing_bound(p.vertices.map(|i| d[i as usize]), p.edge_edge, self.relative_motion);
            if bound > 0.0 {
                let (gap, _, _) = self.self_distance(p, y);
                let mut limit = 0.9 * gap / bound;
                if limit < 1.0 {
                    // The bound takes any motion as closing the gap, so a pair in contact
                    // that slides or parts would hold the whole cloth's step to a sliver
                    // of it (0.5 % for a hundred iterations on the sphere drop). Where the
                    // bound would cut the step, the pair's own path along d decides: up to
                    // nine tenths of the way to where it would cross, all of d if it
                    // does not.
                    limit = limit.max(0.9 * crossing_time(p, gap, y, d).unwrap_or(1.0 / 0.9));
                }
                alpha = alpha.min(limit);
            }
        }
        alpha.max(0.0)
    }

    /// The rank-one Gauss–Newton terms of the active cloth–cloth pairs at `y`.
    pub fn couplings(&self, y: &[DVec3], out: &mut Vec<Coupling>) {
        for p in &self.pairs {
            let (d, n, w) = self.self_distance(p, y);
            if d < self.self_thickness {
                out.push(Coupling {
                    vertices: p.vertices,
                    weights: w,
                    normal: n,
                    stiffness: p.stiffness,
                });
            }
        }
    }
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// The earliest fraction of `d` from `y` at which pair `p`, `gap` apart, would cross (meet
/// within a thousandth of that gap), if it does within the whole of d.
fn crossing_time(p: &SelfPair, gap: f64, y: &[DVec3], d: &[DVec3]) -> Option<f64> {
    let path = |i: u32| [y[i as usize], y[i as usize] + d[i as usize]];
    let [a, b, c, e] = p.vertices.map(path);
    if p.edge_edge { edge_edge_ccd(a, b, c, e, 1e-3 * gap) } else { vertex_triangle_ccd(a, b, c, e, 1e-3 * gap) }
}
