//! Quickhull: the convex hull of a point cloud as outward triangles, for the mass properties
//! of a convex hull (`f64` throughout; the points are widened first).

use glam::DVec3;

use super::HullError;
use crate::math::{Vec3, Widen};

/// The hull of `points` as vertices (in `f64`) and outward triangles (see `quickhull`).
pub(super) fn hull_triangles(points: &[Vec3]) -> Result<(Vec<DVec3>, Vec<[u32; 3]>), HullError> {
    let vertices: Vec<DVec3> = points.iter().map(|p| p.widen()).collect();
    let triangles = quickhull(&vertices)?;
    Ok((vertices, triangles))
}

/// One triangle of the hull under construction. Edge `i` runs from `v[i]` to `v[(i + 1) % 3]`;
/// `neighbors[i]` is the face across it. Points of `outside` lie above the face's plane.
struct Face {
    v: [u32; 3],
    neighbors: [u32; 3],
    normal: DVec3,
    offset: f64,
    outside: Vec<u32>,
    /// The point of `outside` farthest above the plane.
    farthest: u32,
    farthest_distance: f64,
    alive: bool,
}

impl Face {
    fn new(v: [u32; 3], points: &[DVec3]) -> Self {
        let [a, b, c] = v.map(|i| points[i as usize]);
        // A degenerate (zero-area) face gets a zero normal: no point is ever above it.
        let normal = (b - a).cross(c - a).normalize_or_zero();
        Self {
            v,
            neighbors: [u32::MAX; 3],
            normal,
            offset: normal.dot(a),
            outside: Vec::new(),
            farthest: u32::MAX,
            farthest_distance: 0.0,
            alive: true,
        }
    }

    fn distance(&self, p: DVec3) -> f64 {
        self.normal.dot(p) - self.offset
    }

    /// Takes point `i` into `outside` if it is more than `eps` above the plane.
    fn take(&mut self, i: u32, points: &[DVec3], eps: f64) -> bool {
        let d = self.distance(points[i as usize]);
        if d > eps {
            if d > self.farthest_distance {
                self.farthest = i;
                self.farthest_distance = d;
            }
            self.outside.push(i);
            true
        } else {
            false
        }
    }

    /// Which edge of this face runs from `a` to `b`.
    fn edge(&self, a: u32, b: u32) -> Option<usize> {
        (0..3).find(|&i| self.v[i] == a && self.v[(i + 1) % 3] == b)
    }
}

/// The convex hull of `points` as outward-oriented triangles (indices into `points`), by
/// Quickhull (Barber, Dobkin & Huhdanpaa 1996) in `f64`: each point is kept by one face it lies
/// above, each step adds the farthest point of a face and replaces the faces it sees by a cone,
/// so each point is looked at `O(log n)` times on average: `O(n log n)` for the usual inputs,
/// including every point on the hull (parry 0.31's hull is quadratic there: 25 s for 4e5
/// points on a sphere).
///
/// Points within `eps = 1e-11 × max |coordinate|` of a face's plane count as inside: the hull
/// may cut off such a sliver, which moves its volume by less than `eps × area`. A point set
/// whose floating-point hull is not a simple surface (the horizon of a step is not one loop)
/// is reported as [`HullError::Failed`] instead of giving a wrong answer.
fn quickhull(points: &[DVec3]) -> Result<Vec<[u32; 3]>, HullError> {
    let scale = points
        .iter()
        .fold(0.0_f64, |m, p| m.max(p.abs().max_element()));
    let eps = 1e-11 * scale;
    let [i0, i1, i2, i3] = initial_tetrahedron(points, eps)?;
    let mut faces = vec![
        Face::new([i0, i1, i2], points),
        Face::new([i0, i3, i1], points),
        Face::new([i1, i3, i2], points),
        Face::new([i2, i3, i0], points),
    ];
    link_all(&mut faces)?;
    for i in 0..points.len() as u32 {
        if [i0, i1, i2, i3].contains(&i) {
            continue;
        }
        for f in faces.iter_mut() {
            if f.take(i, points, eps) {
                break;
            }
        }
    }
    expand(&mut faces, points, eps)?;
    Ok(faces.iter().filter(|f| f.alive).map(|f| f.v).collect())
}

/// The initial tetrahedron: the farthest pair among the axis extremes, the point farthest from
/// their line, the point farthest from their plane; the base `(i0, i1, i2)` oriented so that
/// `i3` is below it. An error when the points span less than a volume (within `eps`).
fn initial_tetrahedron(points: &[DVec3], eps: f64) -> Result<[u32; 4], HullError> {
    let mut extremes = [0usize; 6];
    for (i, p) in points.iter().enumerate() {
        for axis in 0..3 {
            if p[axis] < points[extremes[2 * axis]][axis] {
                extremes[2 * axis] = i;
            }
            if p[axis] > points[extremes[2 * axis + 1]][axis] {
                extremes[2 * axis + 1] = i;
            }
        }
    }
    let flat = |shape, thickness| HullError::Flat {
        shape,
        thickness,
        tolerance: eps,
    };
    let mut best = (0.0, 0, 0);
    for &i in &extremes {
        for &j in &extremes {
            let d = points[i].distance_squared(points[j]);
            if d > best.0 {
                best = (d, i, j);
            }
        }
    }
    let (i0, i1) = (best.1, best.2);
    let span = best.0.sqrt();
    if span <= eps {
        return Err(flat("point", span));
    }
    let (p0, p1) = (points[i0], points[i1]);
    let line = (p1 - p0).normalize();
    // The point farthest by `distance` from p0 (the first of equals), with that distance.
    let farthest = |distance: &dyn Fn(DVec3) -> f64| {
        points
            .iter()
            .enumerate()
            .map(|(i, p)| (distance(*p - p0), i))
            .fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a })
    };
    let (d2, i2) = farthest(&|d| d.reject_from_normalized(line).length());
    if d2 <= eps {
        return Err(flat("line", d2));
    }
    let plane = (p1 - p0).cross(points[i2] - p0).normalize();
    let (d3, i3) = farthest(&|d| d.dot(plane).abs());
    if d3 <= eps {
        return Err(flat("plane", d3));
    }
    let [i0, i1, i2, i3] = [i0, i1, i2, i3].map(|i| i as u32);
    // Orient the base (i0, i1, i2) so that i3 is below it.
    let (i1, i2) = if (points[i3 as usize] - p0).dot(plane) > 0.0 {
        (i2, i1)
    } else {
        (i1, i2)
    };
    Ok([i0, i1, i2, i3])
}

/// Grows the hull `faces` (each holding the points above it) until no face has a point above
/// it: each step takes a face's farthest point (the eye), removes the faces the eye sees and
/// closes the hole with a cone of new faces from its horizon to the eye.
fn expand(faces: &mut Vec<Face>, points: &[DVec3], eps: f64) -> Result<(), HullError> {
    let mut pending: Vec<u32> = (0..4).collect();
    let mut step = Expansion::default();
    step.seen.resize(4, 0);
    while let Some(f) = pending.pop() {
        let face = &faces[f as usize];
        if !face.alive || face.outside.is_empty() {
            continue;
        }
        let eye = face.farthest;
        step.find_visible(faces, f, points[eye as usize], eps);
        // The visible faces go (their slots are reused: only other visible faces point to
        // them); their points move to a new face they are above, or are inside.
        step.orphans.clear();
        for &g in &step.visible {
            let face = &mut faces[g as usize];
            face.alive = false;
            step.orphans.extend(std::mem::take(&mut face.outside));
            step.free.push(g);
        }
        step.build_cone(faces, points, eye)?;
        for &p in &step.orphans {
            if p == eye {
                continue;
            }
            for &id in &step.created {
                if faces[id as usize].take(p, points, eps) {
                    break;
                }
            }
        }
        pending.extend_from_slice(&step.created);
    }
    Ok(())
}

/// The working sets of one step of [`expand`], kept across steps.
#[derive(Default)]
struct Expansion {
    /// The faces the eye sees.
    visible: Vec<u32>,
    /// The walk's stack.
    stack: Vec<u32>,
    /// Per face, the stamp of the last walk that reached it.
    seen: Vec<u32>,
    /// This walk's stamp.
    stamp: u32,
    /// Horizon edges `(a, b, the face across)`.
    horizon: Vec<(u32, u32, u32)>,
    /// The cone's face starting at each horizon vertex.
    starts: std::collections::HashMap<u32, u32>,
    /// The points of the removed faces.
    orphans: Vec<u32>,
    /// Slots of removed faces, for reuse.
    free: Vec<u32>,
    /// The cone's faces.
    created: Vec<u32>,
}

impl Expansion {
    /// Finds the faces the eye at `eye_point` sees, a connected patch around `f` (a walk over
    /// neighbours), and their horizon: the edges from a visible face to one that is not.
    fn find_visible(&mut self, faces: &[Face], f: u32, eye_point: DVec3, eps: f64) {
        self.stamp += 1;
        let stamp = self.stamp;
        self.seen.resize(faces.len(), 0);
        self.visible.clear();
        self.horizon.clear();
        self.stack.clear();
        self.stack.push(f);
        self.seen[f as usize] = stamp;
        while let Some(g) = self.stack.pop() {
            self.visible.push(g);
            for e in 0..3 {
                let n = faces[g as usize].neighbors[e];
                if self.seen[n as usize] == stamp {
                    continue;
                }
                if faces[n as usize].distance(eye_point) > eps {
                    self.seen[n as usize] = stamp;
                    self.stack.push(n);
                }
            }
        }
        for &g in &self.visible {
            let face = &faces[g as usize];
            for e in 0..3 {
                let n = face.neighbors[e];
                if self.seen[n as usize] != stamp {
                    self.horizon.push((face.v[e], face.v[(e + 1) % 3], n));
                }
            }
        }
    }

    /// A cone of new faces from the horizon to the eye, in the free slots first, linked to
    /// their neighbours across the horizon and to each other.
    fn build_cone(
        &mut self,
        faces: &mut Vec<Face>,
        points: &[DVec3],
        eye: u32,
    ) -> Result<(), HullError> {
        self.starts.clear();
        self.created.clear();
        for &(a, b, n) in &self.horizon {
            let face = Face::new([a, b, eye], points);
            let id = match self.free.pop() {
                Some(id) => {
                    faces[id as usize] = face;
                    id
                }
                None => {
                    faces.push(face);
                    faces.len() as u32 - 1
                }
            };
            faces[id as usize].neighbors[0] = n;
            let across = faces[n as usize]
                .edge(b, a)
                .ok_or_else(|| HullError::Failed("hull surface is not closed".into()))?;
            faces[n as usize].neighbors[across] = id;
            if self.starts.insert(a, id).is_some() {
                return Err(HullError::Failed(
                    "the horizon of a step is not one loop (points too close to coplanar)".into(),
                ));
            }
            self.created.push(id);
        }
        for (&id, &(_, b, _)) in self.created.iter().zip(&self.horizon) {
            let next = *self
                .starts
                .get(&b)
                .ok_or_else(|| HullError::Failed("the horizon of a step is not one loop".into()))?;
            faces[id as usize].neighbors[1] = next;
            faces[next as usize].neighbors[2] = id;
        }
        Ok(())
    }
}

/// Links the neighbours of the initial tetrahedron's faces.
fn link_all(faces: &mut [Face]) -> Result<(), HullError> {
    for i in 0..faces.len() {
        for e in 0..3 {
            let (a, b) = (faces[i].v[e], faces[i].v[(e + 1) % 3]);
            let j = (0..faces.len())
                .find(|&j| faces[j].edge(b, a).is_some())
                .ok_or_else(|| HullError::Failed("initial tetrahedron is not closed".into()))?;
            faces[i].neighbors[e] = j as u32;
        }
    }
    Ok(())
}
