//! The editable triangle mesh ([`EditMesh`]) with the local operators every stage that changes a
//! triangulation uses; its representation and rules are described on [`EditMesh`].

use glam::DVec3;
use rustc_hash::{FxHashMap, FxHashSet};

use crate::geometry::triangle::is_degenerate_triangle;
use crate::mesh::TriMesh;

/// Where the faces an operator makes go.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlotPolicy {
    /// Every new face takes a new slot at the end; the faces it replaces leave dead slots. The
    /// live faces stay in the order they were made.
    Append,
    /// A face made from an old one (the first new face of each old face an operator replaces)
    /// takes the old face's slot; other new faces are appended. Faces no operator touched keep
    /// their slot, so their index in the input stays their index.
    Reuse,
}

/// Why an operator refused: the mesh is unchanged.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EditError {
    /// A face would repeat a vertex.
    RepeatedCorner {
        /// The face.
        face: [u32; 3],
    },
    /// A vertex index is out of range.
    NoSuchVertex {
        /// The vertex.
        vertex: u32,
    },
    /// The slot holds no live face.
    NoSuchFace {
        /// The slot.
        face: u32,
    },
    /// A directed edge of a new face is used by another face or blocked.
    EdgeInUse {
        /// The directed edge.
        edge: [u32; 2],
    },
    /// The face would be the reverse of an existing face (the two would close on themselves).
    ReverseOfFace {
        /// The new face.
        face: [u32; 3],
        /// The slot of the existing face.
        existing: u32,
    },
    /// A new face would have no area ([`is_degenerate_triangle`]).
    Degenerate {
        /// The face.
        face: [u32; 3],
    },
    /// The edge has no face on one of its sides (or on neither).
    NotInteriorEdge {
        /// The edge, as given.
        edge: [u32; 2],
    },
    /// A flip would make an edge that is already there (or whose direction is blocked).
    FlipWouldDuplicateEdge {
        /// The edge the flip would make.
        edge: [u32; 2],
    },
    /// A collapse would break the link condition: the ends share a neighbour other than the two
    /// opposite vertices, an opposite vertex has only three faces, or both ends are on the
    /// boundary while the edge is not.
    LinkCondition {
        /// The edge, `[removed, kept]`.
        edge: [u32; 2],
    },
    /// A split needs a vertex no face uses yet.
    VertexInUse {
        /// The vertex.
        vertex: u32,
    },
    /// A vertex cannot move to a non-finite position.
    NonFinitePosition {
        /// The vertex.
        vertex: u32,
    },
    /// A flip or collapse would remove or move a protected edge (a crease kept as an edge).
    ProtectedEdge {
        /// The edge.
        edge: [u32; 2],
    },
}

/// An invariant that [`EditMesh::sanity_check`] found broken.
#[derive(Debug, Clone, PartialEq)]
pub enum EditViolation {
    /// A live face repeats a vertex or has an index out of range.
    BadFace {
        /// The slot.
        face: u32,
        /// Its corners.
        corners: [u32; 3],
    },
    /// A live face has no area.
    DegenerateFace {
        /// The slot.
        face: u32,
    },
    /// Two live faces use the same directed edge (a non-manifold edge or inconsistent
    /// orientation), or the edge table does not say which face uses it.
    DirectedEdge {
        /// The directed edge.
        edge: [u32; 2],
        /// The face the table names (`None`: none).
        table: Option<u32>,
        /// The face that uses it.
        face: u32,
    },
    /// The edge table names a face that does not use the edge (or is dead).
    StaleEdge {
        /// The directed edge.
        edge: [u32; 2],
        /// The face the table names.
        face: u32,
    },
    /// A face uses a blocked direction.
    BlockedEdgeUsed {
        /// The directed edge.
        edge: [u32; 2],
    },
    /// Two live faces have the same three vertices.
    DuplicateFace {
        /// The slots.
        faces: [u32; 2],
    },
    /// The faces around a vertex do not form one fan.
    NonManifoldVertex {
        /// The vertex.
        vertex: u32,
        /// How many fans.
        fans: usize,
    },
    /// The vertex–face lists disagree with the faces.
    VertexFaces {
        /// The vertex.
        vertex: u32,
    },
}

/// Rotates `t` so that it starts with `v` (which must be a corner).
pub fn starting_at(t: [u32; 3], v: u32) -> [u32; 3] {
    if t[0] == v {
        t
    } else if t[1] == v {
        [t[1], t[2], t[0]]
    } else {
        [t[2], t[0], t[1]]
    }
}

/// An editable triangle mesh: faces in slots, a directed-edge table and vertex–face lists, and
/// the local operators every stage that changes a triangulation uses (the assembly's hole filling
/// and refinement, the optimizer, untangling): edge flip, edge split, face split, edge collapse
/// (with the link condition), vertex relocation, face removal and hole filling. Each operator
/// checks that its result keeps the invariants [`EditMesh::sanity_check`] verifies and refuses
/// (with an [`EditError`], the mesh unchanged) when it would not.
///
/// The representation is the directed-edge one (Campagna, Kobbelt, Seidel, "Directed edges — a
/// scalable representation for triangle meshes", J. Graphics Tools 3(4), 1998,
/// doi:10.1080/10867651.1998.10487494) with a hash map from directed edge to face instead of
/// implicit half-edge indices, so faces can come and go in any order. Every directed edge is used
/// by at most one face: that single rule keeps every edge in at most two faces and the
/// orientation consistent.
///
/// Some directed edges can be *blocked*: no face may use them (the outside of an open input's
/// boundary, so that its boundary edges stay boundary edges).
///
/// Faces live in slots `0..slots()`; a removed face leaves a dead slot, so face indices stay
/// valid. Each face carries a label of type `L` (where it came from), given by whoever makes it.
#[derive(Debug, Clone)]
pub struct EditMesh<L: Copy = ()> {
    positions: Vec<DVec3>,
    faces: Vec<[u32; 3]>,
    alive: Vec<bool>,
    labels: Vec<L>,
    /// Directed edge → the face that uses it.
    edge: FxHashMap<(u32, u32), u32>,
    /// Directed edges no face may use.
    blocked: FxHashSet<(u32, u32)>,
    /// Undirected edges `(min, max)` that flips and collapses keep.
    protected: FxHashSet<(u32, u32)>,
    /// Vertex → the live faces around it.
    around: Vec<Vec<u32>>,
    policy: SlotPolicy,
    /// What changed since [`EditMesh::track_changes`] or the last [`EditMesh::take_changes`]
    /// (`None`: not tracked).
    changes: Option<Changes>,
}

/// What changed in an [`EditMesh`] while it tracked its changes ([`EditMesh::track_changes`]),
/// each in the order it happened, with repeats: what a pass that keeps a set of faces up to
/// date (the finishing stage's poor faces) looks at again, instead of every face.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Changes {
    /// Face slots whose face was made, replaced or removed.
    pub faces: Vec<u32>,
    /// Vertices given a new position (moves tried and taken back too).
    pub vertices: Vec<u32>,
}

impl<L: Copy> EditMesh<L> {
    /// A mesh of the vertices `positions` and no faces.
    pub fn new(positions: Vec<DVec3>, policy: SlotPolicy) -> Self {
        let n = positions.len();
        EditMesh {
            positions,
            faces: Vec::new(),
            alive: Vec::new(),
            labels: Vec::new(),
            edge: FxHashMap::default(),
            blocked: FxHashSet::default(),
            protected: FxHashSet::default(),
            around: vec![Vec::new(); n],
            policy,
            changes: None,
        }
    }

    /// From now on, records the faces made, replaced or removed and the vertices moved
    /// ([`Changes`]), until [`EditMesh::take_changes`] takes them.
    pub fn track_changes(&mut self) {
        self.changes = Some(Changes::default());
    }

    /// The changes recorded since [`EditMesh::track_changes`] or the last call (none when not
    /// tracking); the record starts again empty.
    pub fn take_changes(&mut self) -> Changes {
        self.changes
            .as_mut()
            .map(std::mem::take)
            .unwrap_or_default()
    }

    /// Stops recording changes (and drops those not taken).
    pub fn stop_tracking(&mut self) {
        self.changes = None;
    }

    fn record_move(&mut self, v: u32) {
        if let Some(c) = &mut self.changes {
            c.vertices.push(v);
        }
    }

    /// The mesh of `mesh`'s vertices and faces, face `f` in slot `f` with label `label(f)`. The
    /// faces are taken as they are (no operator checks; [`EditMesh::sanity_check`] tells whether
    /// they are manifold and consistently oriented; where two faces use the same directed edge,
    /// the table names the later one).
    ///
    /// # Panics
    /// When a face has an index out of range ([`TriMesh::check_indices`] finds those first).
    pub fn from_trimesh(mesh: &TriMesh, label: impl Fn(u32) -> L, policy: SlotPolicy) -> Self {
        let mut m = EditMesh::new(mesh.positions.clone(), policy);
        m.faces.reserve(mesh.triangles.len());
        for (f, &t) in mesh.triangles.iter().enumerate() {
            m.push(t, label(f as u32));
        }
        m
    }

    /// Blocks the directed edge `a → b`: no face may use it.
    pub fn block_directed_edge(&mut self, a: u32, b: u32) {
        self.blocked.insert((a, b));
    }

    /// Protects the edge `a`–`b` (whether or not a face uses it yet): no flip removes it and no
    /// collapse removes or moves it ([`EditError::ProtectedEdge`]). The creases a remesh keeps.
    pub fn protect_edge(&mut self, a: u32, b: u32) {
        self.protected.insert((a.min(b), a.max(b)));
    }

    /// Whether the edge `a`–`b` is protected ([`EditMesh::protect_edge`]).
    pub fn is_protected(&self, a: u32, b: u32) -> bool {
        !self.protected.is_empty() && self.protected.contains(&(a.min(b), a.max(b)))
    }

    /// Whether a protected edge ends at `v`.
    fn has_protected_edge(&self, v: u32) -> bool {
        !self.protected.is_empty() && self.ring(v).into_iter().any(|u| self.is_protected(u, v))
    }

    /// The number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// The number of face slots, dead ones included.
    pub fn slots(&self) -> usize {
        self.faces.len()
    }

    /// The vertex positions.
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// The position of vertex `v`.
    pub fn position(&self, v: u32) -> DVec3 {
        self.positions[v as usize]
    }

    /// The corner positions of `t`.
    pub fn corners(&self, t: [u32; 3]) -> [DVec3; 3] {
        t.map(|i| self.positions[i as usize])
    }

    /// The face in slot `f`, `None` when the slot is dead or out of range.
    pub fn face(&self, f: u32) -> Option<[u32; 3]> {
        let i = f as usize;
        (i < self.faces.len() && self.alive[i]).then(|| self.faces[i])
    }

    /// The label of the face in slot `f` (the last face that lived there).
    pub fn label(&self, f: u32) -> L {
        self.labels[f as usize]
    }

    /// The face that uses the directed edge `a → b`.
    pub fn face_on(&self, a: u32, b: u32) -> Option<u32> {
        self.edge.get(&(a, b)).copied()
    }

    /// Whether the directed edge `a → b` is used by a face or blocked.
    pub fn is_used_or_blocked(&self, a: u32, b: u32) -> bool {
        self.edge.contains_key(&(a, b)) || self.blocked.contains(&(a, b))
    }

    /// Whether a face uses the edge `a`–`b` in either direction.
    pub fn has_edge(&self, a: u32, b: u32) -> bool {
        self.edge.contains_key(&(a, b)) || self.edge.contains_key(&(b, a))
    }

    /// The directed edges used by faces, in no particular order.
    pub fn directed_edges(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.edge.keys().copied()
    }

    /// The slots of the live faces around `v`.
    pub fn faces_around(&self, v: u32) -> &[u32] {
        &self.around[v as usize]
    }

    /// The number of live faces around `v`.
    pub fn degree(&self, v: u32) -> usize {
        self.around[v as usize].len()
    }

    /// The vertices sharing a face with `v`, sorted.
    pub fn ring(&self, v: u32) -> Vec<u32> {
        let mut r: Vec<u32> = self.around[v as usize]
            .iter()
            .flat_map(|&f| self.faces[f as usize])
            .filter(|&u| u != v)
            .collect();
        r.sort_unstable();
        r.dedup();
        r
    }

    /// Whether `v` is on a boundary edge (an edge with a face on one side only). Only the two
    /// edges of each face around `v` that end at `v` count: a vertex whose faces touch the
    /// boundary elsewhere is not on it.
    pub fn is_boundary_vertex(&self, v: u32) -> bool {
        self.around[v as usize].iter().any(|&f| {
            let [_, a, b] = starting_at(self.faces[f as usize], v);
            !self.edge.contains_key(&(a, v)) || !self.edge.contains_key(&(v, b))
        })
    }

    /// The half-edges bordering holes, sorted: `b → a` for every face edge `a → b` whose reverse
    /// is neither used nor blocked. Walking them closes each hole counter-clockwise.
    pub fn boundary_half_edges(&self) -> Vec<(u32, u32)> {
        let mut out: Vec<(u32, u32)> = self
            .edge
            .keys()
            .map(|&(a, b)| (b, a))
            .filter(|&(b, a)| !self.is_used_or_blocked(b, a))
            .collect();
        out.sort_unstable();
        out
    }

    /// The live faces and, for each, its slot.
    pub fn live_faces(&self) -> (Vec<[u32; 3]>, Vec<u32>) {
        (0..self.faces.len() as u32)
            .filter(|&f| self.alive[f as usize])
            .map(|f| (self.faces[f as usize], f))
            .unzip()
    }

    /// The indexed mesh of the vertices and the live faces (in slot order).
    pub fn to_trimesh(&self) -> TriMesh {
        TriMesh::new(self.positions.clone(), self.live_faces().0)
    }

    /// The vertex positions, the live faces in slot order, and their labels.
    pub fn into_parts(self) -> (Vec<DVec3>, Vec<[u32; 3]>, Vec<L>) {
        let mut faces = Vec::new();
        let mut labels = Vec::new();
        for (f, &t) in self.faces.iter().enumerate() {
            if self.alive[f] {
                faces.push(t);
                labels.push(self.labels[f]);
            }
        }
        (self.positions, faces, labels)
    }

    /// Adds a vertex no face uses and returns its index.
    pub fn add_vertex(&mut self, p: DVec3) -> u32 {
        self.positions.push(p);
        self.around.push(Vec::new());
        (self.positions.len() - 1) as u32
    }

    /// Removes the last vertex if no face uses it; returns its position.
    pub fn pop_vertex(&mut self) -> Option<DVec3> {
        if self.around.last().is_some_and(|a| a.is_empty()) {
            self.around.pop();
            self.positions.pop()
        } else {
            None
        }
    }

    /// Vertex relocation: moves `v` to `p`. The connectivity is unchanged; whether the faces
    /// around `v` keep their shape and orientation is the caller's test.
    pub fn relocate_vertex(&mut self, v: u32, p: DVec3) -> Result<(), EditError> {
        if v as usize >= self.positions.len() {
            return Err(EditError::NoSuchVertex { vertex: v });
        }
        if !p.is_finite() {
            return Err(EditError::NonFinitePosition { vertex: v });
        }
        self.positions[v as usize] = p;
        self.record_move(v);
        Ok(())
    }

    /// Why `t` could not be added, if it could not: a repeated or out-of-range corner, a directed
    /// edge used or blocked, the reverse of an existing face, or no area (three samples on a
    /// line: found by the triangulate fuzz target, where a hole of three collinear samples was
    /// closed by a flat triangle).
    pub fn check_new_face(&self, t: [u32; 3]) -> Result<(), EditError> {
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            return Err(EditError::RepeatedCorner { face: t });
        }
        if let Some(&v) = t.iter().find(|&&v| v as usize >= self.positions.len()) {
            return Err(EditError::NoSuchVertex { vertex: v });
        }
        self.check_fits(t)?;
        if is_degenerate_triangle(self.corners(t)) {
            return Err(EditError::Degenerate { face: t });
        }
        Ok(())
    }

    /// Whether `t` fits: none of its directed edges is used or blocked, and it is not the reverse
    /// of an existing face (the two would close on themselves as a flat pillow). Corners and
    /// area are not looked at (see [`EditMesh::check_new_face`]).
    pub fn fits(&self, t: [u32; 3]) -> bool {
        self.check_fits(t).is_ok()
    }

    fn check_fits(&self, t: [u32; 3]) -> Result<(), EditError> {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if self.is_used_or_blocked(a, b) {
                return Err(EditError::EdgeInUse { edge: [a, b] });
            }
        }
        if let Some(f) = self.face_on(t[1], t[0]) {
            if self.face_on(t[2], t[1]) == Some(f) && self.face_on(t[0], t[2]) == Some(f) {
                return Err(EditError::ReverseOfFace {
                    face: t,
                    existing: f,
                });
            }
        }
        Ok(())
    }

    /// Adds the face `t` in a new slot at the end, when [`EditMesh::check_new_face`] allows it.
    /// Returns the slot.
    pub fn add_face(&mut self, t: [u32; 3], label: L) -> Result<u32, EditError> {
        self.check_new_face(t)?;
        Ok(self.push(t, label))
    }

    /// Face removal: removes the face in slot `f` (its slot stays, dead).
    pub fn remove_face(&mut self, f: u32) -> Result<(), EditError> {
        if self.face(f).is_none() {
            return Err(EditError::NoSuchFace { face: f });
        }
        self.unlink(f);
        self.alive[f as usize] = false;
        Ok(())
    }

    /// Hole filling: adds the faces `triangles` (for example a triangulation of a hole's
    /// boundary loop), all of them or, when one of them does not pass
    /// [`EditMesh::check_new_face`] after the ones before it are in, none (the error names the
    /// first that failed). Returns their slots, in order.
    pub fn fill_hole(&mut self, triangles: &[[u32; 3]], label: L) -> Result<Vec<u32>, EditError> {
        let mut added = Vec::with_capacity(triangles.len());
        for &t in triangles {
            match self.add_face(t, label) {
                Ok(f) => added.push(f),
                Err(e) => {
                    for f in added {
                        self.unlink(f);
                        self.alive[f as usize] = false;
                    }
                    return Err(e);
                }
            }
        }
        Ok(added)
    }

    /// The two faces of the interior edge `a`–`b`, `[a, b, c]` and `[b, a, d]`, with their
    /// slots: `(f1, f2, c, d)`.
    pub fn edge_faces(&self, a: u32, b: u32) -> Result<(u32, u32, u32, u32), EditError> {
        let (Some(f1), Some(f2)) = (self.face_on(a, b), self.face_on(b, a)) else {
            return Err(EditError::NotInteriorEdge { edge: [a, b] });
        };
        let c = starting_at(self.faces[f1 as usize], a)[2];
        let d = starting_at(self.faces[f2 as usize], b)[2];
        Ok((f1, f2, c, d))
    }

    /// Edge flip: the interior edge `a`–`b` with faces `[a, b, c]` and `[b, a, d]` becomes
    /// `c`–`d`, with faces `[a, d, c]` and `[b, c, d]` (in that order, placed by the
    /// [`SlotPolicy`]). Refused for a boundary edge, when `c`–`d` is already an edge (or a
    /// blocked direction), or when a new face has no area. Returns the new faces' slots.
    pub fn flip_edge(&mut self, a: u32, b: u32, label: L) -> Result<[u32; 2], EditError> {
        let (f1, f2, c, d) = self.edge_faces(a, b)?;
        if self.is_protected(a, b) {
            return Err(EditError::ProtectedEdge { edge: [a, b] });
        }
        if c == d || self.is_used_or_blocked(c, d) || self.is_used_or_blocked(d, c) {
            return Err(EditError::FlipWouldDuplicateEdge { edge: [c, d] });
        }
        let (new1, new2) = ([a, d, c], [b, c, d]);
        for t in [new1, new2] {
            if is_degenerate_triangle(self.corners(t)) {
                return Err(EditError::Degenerate { face: t });
            }
        }
        let g1 = self.replace(f1, new1, label);
        let g2 = self.replace(f2, new2, label);
        Ok([g1, g2])
    }

    /// Face split: the face in slot `f`, `[a, b, c]`, becomes `[a, b, v]`, `[b, c, v]`,
    /// `[c, a, v]` around the vertex `v`, which no face may use yet. Refused when a new face has
    /// no area or uses a blocked direction. Returns the new faces' slots, in that order.
    pub fn split_face(&mut self, f: u32, v: u32, label: L) -> Result<[u32; 3], EditError> {
        let t = self.face(f).ok_or(EditError::NoSuchFace { face: f })?;
        self.check_unused_vertex(v)?;
        let [a, b, c] = t;
        let new = [[a, b, v], [b, c, v], [c, a, v]];
        self.check_new_at(&new, v)?;
        let g0 = self.replace(f, new[0], label);
        let g1 = self.push(new[1], label);
        let g2 = self.push(new[2], label);
        Ok([g0, g1, g2])
    }

    /// Edge split: the interior edge `a`–`b` with faces `[a, b, c]` and `[b, a, d]` is split at
    /// the vertex `v`, which no face may use yet: the faces become `[a, v, c]`, `[v, b, c]`,
    /// `[b, v, d]`, `[v, a, d]`. Refused for a boundary edge, or when a new face has no area or
    /// uses a blocked direction. Returns the new faces' slots, in that order.
    pub fn split_edge(&mut self, a: u32, b: u32, v: u32, label: L) -> Result<[u32; 4], EditError> {
        let (f1, f2, c, d) = self.edge_faces(a, b)?;
        self.check_unused_vertex(v)?;
        let new = [[a, v, c], [v, b, c], [b, v, d], [v, a, d]];
        self.check_new_at(&new, v)?;
        let g0 = self.replace(f1, new[0], label);
        let g1 = self.push(new[1], label);
        let g2 = self.replace(f2, new[2], label);
        let g3 = self.push(new[3], label);
        Ok([g0, g1, g2, g3])
    }

    /// Edge collapse: the interior edge `removed`–`kept` shrinks to the vertex `kept`, moved to
    /// `position`; the two faces of the edge go, and every other face of `removed` takes `kept`
    /// in its place (keeping its slot or not by the [`SlotPolicy`], with `label`). `removed` is
    /// left in no face. Refused unless the link condition holds (the two ends share exactly the
    /// two opposite vertices, each of those has more than three faces, and the ends are not
    /// both on the boundary), or when a changed face would have no area.
    pub fn collapse_edge(
        &mut self,
        removed: u32,
        kept: u32,
        position: DVec3,
        label: L,
    ) -> Result<(), EditError> {
        let (f1, f2, c, d) = self.edge_faces(removed, kept)?;
        // A protected edge at `removed` would go or move; one at `kept` moves unless `kept`
        // stays where it is.
        if self.has_protected_edge(removed)
            || (position != self.positions[kept as usize] && self.has_protected_edge(kept))
        {
            return Err(EditError::ProtectedEdge {
                edge: [removed, kept],
            });
        }
        let link = Err(EditError::LinkCondition {
            edge: [removed, kept],
        });
        let (ra, rb) = (self.ring(removed), self.ring(kept));
        let common: Vec<u32> = ra.iter().copied().filter(|u| rb.contains(u)).collect();
        if c == d
            || common.len() != 2
            || !common.contains(&c)
            || !common.contains(&d)
            || self.degree(c) <= 3
            || self.degree(d) <= 3
            || (self.is_boundary_vertex(removed) && self.is_boundary_vertex(kept))
        {
            return link;
        }
        if !position.is_finite() {
            return Err(EditError::NonFinitePosition { vertex: kept });
        }
        let corner = |u: u32| {
            if u == kept || u == removed {
                position
            } else {
                self.positions[u as usize]
            }
        };
        for &g in self.around[removed as usize]
            .iter()
            .chain(&self.around[kept as usize])
        {
            if g == f1 || g == f2 {
                continue;
            }
            let t = self.faces[g as usize];
            if is_degenerate_triangle(t.map(corner)) {
                return Err(EditError::Degenerate {
                    face: t.map(|u| if u == removed { kept } else { u }),
                });
            }
        }
        for f in [f1, f2] {
            self.unlink(f);
            self.alive[f as usize] = false;
        }
        for g in self.around[removed as usize].clone() {
            let t = self.faces[g as usize].map(|u| if u == removed { kept } else { u });
            self.replace(g, t, label);
        }
        self.positions[kept as usize] = position;
        self.record_move(kept);
        Ok(())
    }

    /// Checks every invariant: live faces have three distinct in-range corners and an area;
    /// every directed edge is used by at most one face and the edge table says which (so every
    /// edge is in at most two faces, oriented oppositely); no face uses a blocked direction; no
    /// two faces have the same three vertices; the faces around every vertex form one fan; the
    /// vertex–face lists match the faces. Returns the first violation found.
    pub fn sanity_check(&self) -> Result<(), EditViolation> {
        let n = self.positions.len();
        let mut used: FxHashMap<(u32, u32), u32> = FxHashMap::default();
        let mut vertex_sets: FxHashMap<[u32; 3], u32> = FxHashMap::default();
        let mut around: Vec<Vec<u32>> = vec![Vec::new(); n];
        for (f, &t) in self.faces.iter().enumerate() {
            if !self.alive[f] {
                continue;
            }
            let f = f as u32;
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || t.iter().any(|&v| v as usize >= n) {
                return Err(EditViolation::BadFace {
                    face: f,
                    corners: t,
                });
            }
            if is_degenerate_triangle(self.corners(t)) {
                return Err(EditViolation::DegenerateFace { face: f });
            }
            for k in 0..3 {
                let e = (t[k], t[(k + 1) % 3]);
                let table = self.face_on(e.0, e.1);
                if used.insert(e, f).is_some() || table != Some(f) {
                    return Err(EditViolation::DirectedEdge {
                        edge: [e.0, e.1],
                        table,
                        face: f,
                    });
                }
                if self.blocked.contains(&e) {
                    return Err(EditViolation::BlockedEdgeUsed { edge: [e.0, e.1] });
                }
                around[t[k] as usize].push(f);
            }
            let mut key = t;
            key.sort_unstable();
            if let Some(g) = vertex_sets.insert(key, f) {
                return Err(EditViolation::DuplicateFace { faces: [g, f] });
            }
        }
        if let Some((&(a, b), &f)) = self.edge.iter().find(|(e, _)| !used.contains_key(e)) {
            return Err(EditViolation::StaleEdge {
                edge: [a, b],
                face: f,
            });
        }
        for (v, faces) in around.iter().enumerate() {
            let mut listed = self.around[v].clone();
            listed.sort_unstable();
            if &listed != faces {
                return Err(EditViolation::VertexFaces { vertex: v as u32 });
            }
            let fans = self.fans_at(v as u32);
            if fans > 1 {
                return Err(EditViolation::NonManifoldVertex {
                    vertex: v as u32,
                    fans,
                });
            }
        }
        Ok(())
    }

    /// The number of fans (faces joined through edges at `v`) around `v`.
    fn fans_at(&self, v: u32) -> usize {
        let faces = &self.around[v as usize];
        let mut seen: FxHashSet<u32> = FxHashSet::default();
        let mut fans = 0;
        for &f in faces {
            if !seen.insert(f) {
                continue;
            }
            fans += 1;
            let mut stack = vec![f];
            while let Some(g) = stack.pop() {
                let t = starting_at(self.faces[g as usize], v);
                // Across v → t[1] and across t[2] → v.
                for h in [self.face_on(t[1], v), self.face_on(v, t[2])]
                    .into_iter()
                    .flatten()
                {
                    if seen.insert(h) {
                        stack.push(h);
                    }
                }
            }
        }
        fans
    }

    fn check_unused_vertex(&self, v: u32) -> Result<(), EditError> {
        if v as usize >= self.positions.len() {
            return Err(EditError::NoSuchVertex { vertex: v });
        }
        if !self.around[v as usize].is_empty() {
            return Err(EditError::VertexInUse { vertex: v });
        }
        Ok(())
    }

    /// Checks the new faces of a split at the unused vertex `v`: no area, or a blocked direction
    /// at `v`.
    fn check_new_at(&self, new: &[[u32; 3]], v: u32) -> Result<(), EditError> {
        for &t in new {
            if is_degenerate_triangle(self.corners(t)) {
                return Err(EditError::Degenerate { face: t });
            }
            for k in 0..3 {
                let e = (t[k], t[(k + 1) % 3]);
                if (e.0 == v || e.1 == v) && self.blocked.contains(&e) {
                    return Err(EditError::EdgeInUse { edge: [e.0, e.1] });
                }
            }
        }
        Ok(())
    }

    /// Appends `t` in a new slot, unchecked.
    fn push(&mut self, t: [u32; 3], label: L) -> u32 {
        let f = self.faces.len() as u32;
        self.faces.push(t);
        self.alive.push(true);
        self.labels.push(label);
        self.link(f);
        f
    }

    /// Puts `t` in place of the face in slot `f`, by the slot policy, unchecked. Returns the
    /// slot of `t`.
    fn replace(&mut self, f: u32, t: [u32; 3], label: L) -> u32 {
        self.unlink(f);
        match self.policy {
            SlotPolicy::Reuse => {
                self.faces[f as usize] = t;
                self.labels[f as usize] = label;
                self.link(f);
                f
            }
            SlotPolicy::Append => {
                self.alive[f as usize] = false;
                self.push(t, label)
            }
        }
    }

    fn link(&mut self, f: u32) {
        if let Some(c) = &mut self.changes {
            c.faces.push(f);
        }
        let t = self.faces[f as usize];
        for k in 0..3 {
            self.edge.insert((t[k], t[(k + 1) % 3]), f);
            self.around[t[k] as usize].push(f);
        }
    }

    /// Removes `f` from the tables (an edge entry only where it names `f`).
    fn unlink(&mut self, f: u32) {
        if let Some(c) = &mut self.changes {
            c.faces.push(f);
        }
        let t = self.faces[f as usize];
        for k in 0..3 {
            let e = (t[k], t[(k + 1) % 3]);
            if self.edge.get(&e) == Some(&f) {
                self.edge.remove(&e);
            }
            self.around[t[k] as usize].retain(|&g| g != f);
        }
    }
}

#[cfg(test)]
mod tests;
