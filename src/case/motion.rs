//! Rigid motions the supports leave free: the infinitesimal rigid motions of the
//! rods that every support and every pin joint allows, found by linear algebra on the
//! natural geometry. A rod moves rigidly by a translation `t` and a rotation `ω`; an end at
//! `X` then moves by `t + ω × X`. What each end holds:
//!
//! | condition | holds |
//! |---|---|
//! | every base, a tip under displacement control | `z` of the end |
//! | `translation = "fixed"` | `x` and `y` |
//! | `translation = "radial"` | the azimuthal direction at the end (x and y on the axis) |
//! | `translation = "slide"` | nothing more |
//! | `rotation = "clamped"` | `ω` |
//! | `rotation = "pinned"` | `ω_z` |
//! | `rotation = "free"` | nothing |
//!
//! and a joint ties the positions of its two rods at the crossing (at an end, in the
//! directions the support leaves free, as the solver ties them); a welded one also their
//! rotations, an elastic one their rotations about the axes it has springs about. A right and a left rod
//! that cross at three points or more move as one body (three points of a helix are never
//! on a line), so the unknowns are six per group of rods tied so; the free motions are the
//! null space of the rows above. The check is exact for the geometry: it names a motion
//! exactly when the stiffness matrix of the natural state has a zero-energy mode
//! (`tests/physics/free_motion.rs` solves every combination of the supports).

use super::settings::Geometry;
use crate::model::assembly::{Assembly, Joint};
use crate::model::boundary::{BoundaryConditions, EndCondition, Joints, Rotation, Translation};
use nalgebra::{DMatrix, Vector3};

/// A rigid motion of the assembly its supports leave free: a zero-energy mode the solver
/// would see as a singular matrix, or the stability count as a neutral direction flipping
/// at every step.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FreeMotion {
    /// The half of the tip's condition a case file names (`translation`, `rotation`).
    pub half: &'static str,
    /// The motion and what to change, in the user's terms.
    pub message: String,
}

/// Groups of rods tied by joints beyond this many are checked as one body (the motions of
/// the whole group; a mechanism inside it is not looked for): only assemblies of many
/// rods so short that their rods cross fewer than three times reach it.
const MAX_GROUPS: usize = 64;

/// A singular value of the rows below this fraction of the largest is a free motion.
const RANK_TOL: f64 = 1e-7;

/// The rigid motion supports `b` leave free on the assembly of `geometry` under `control`
/// (the tip's height is free under load control), if any. The one check of the case
/// reader and of the explorer's condition keys. A motion that sliding crossings free and
/// pins would hold says so.
pub fn free_motion_of(
    b: &BoundaryConditions,
    geometry: &Geometry,
    tip_height_held: bool,
) -> Option<FreeMotion> {
    let mut motion = rigid_motion_of(b, geometry, tip_height_held)?;
    if b.joints.slides() {
        let pinned = BoundaryConditions {
            joints: Joints::Pin,
            ..*b
        };
        if rigid_motion_of(&pinned, geometry, tip_height_held).is_none() {
            motion.message.push_str(
                "; the crossings slide (boundary.joints = \"sliding\"): pinned, they would hold it",
            );
        }
    }
    Some(motion)
}

/// [`free_motion_of`] without the word on sliding crossings.
fn rigid_motion_of(
    b: &BoundaryConditions,
    geometry: &Geometry,
    tip_height_held: bool,
) -> Option<FreeMotion> {
    let n = geometry.helices.max(1);
    let assembly = Assembly::new(n, geometry.radius, geometry.pitch, geometry.length);
    let rods = assembly.rods.len();
    let joints = if b.joints.active() && rods > 1 {
        assembly.joints.as_slice()
    } else {
        &[]
    };
    let supports = Supports {
        assembly: &assembly,
        b,
        joints,
        scale: geometry.length.max(geometry.radius).max(f64::MIN_POSITIVE),
        tip_height_held,
    };
    let length = geometry.length;
    let at_end = |j: &Joint| j.s <= 1e-9 * length || j.s >= length * (1.0 - 1e-9);
    let (mut body, comps) = bodies(rods, joints, |j| !b.joints.slides() || at_end(j));
    let mut seen = Vec::new();
    for &comp in &comps {
        if seen.contains(&comp) {
            continue;
        }
        seen.push(comp);
        let members: Vec<usize> = (0..rods).filter(|&i| comps[i] == comp).collect();
        let groups = bodies_of(&members, &mut body);
        let column = |i: usize| 6 * groups.binary_search(&body[i]).expect("a group");
        let mut gram = Gram(DMatrix::<f64>::zeros(6 * groups.len(), 6 * groups.len()));
        supports.support_rows(&mut gram, &members, &column);
        supports.joint_rows(&mut gram, comp, &comps, &column);
        let free = null_space_of_gram(gram.0);
        if free.is_empty() {
            continue;
        }
        // a translation among the free motions, or else the rod turning fastest in one
        let found = Found {
            assembly: &assembly,
            scale: supports.scale,
            n,
            one_rod: members.len() == 1,
            translation: translation_in(&free, groups.len()),
            turning: fastest_turning(&free, &members, &column),
        };
        return Some(describe(b, &found));
    }
    None
}

/// The root of `i` in the union-find forest `g` (paths halved on the way).
fn root(g: &mut [usize], mut i: usize) -> usize {
    while g[i] != i {
        g[i] = g[g[i]];
        i = g[i];
    }
    i
}

/// The rods as rigid bodies: the body of each rod (right and left rods crossing three times
/// or more at joints that `pinned` says hold a material point of both move as one), and the
/// component of each (bodies tied by the remaining joints).
fn bodies(
    rods: usize,
    joints: &[Joint],
    pinned: impl Fn(&Joint) -> bool,
) -> (Vec<usize>, Vec<usize>) {
    let mut group: Vec<usize> = (0..rods).collect();
    let mut crossings = std::collections::HashMap::<(usize, usize), usize>::new();
    for j in joints.iter().filter(|j| pinned(j)) {
        *crossings.entry((j.right, j.left)).or_default() += 1;
    }
    for (&(r, l), &count) in &crossings {
        if count >= 3 {
            let (a, c) = (root(&mut group, r), root(&mut group, l));
            group[a] = c;
        }
    }
    let body: Vec<usize> = (0..rods).map(|i| root(&mut group, i)).collect();
    let mut comp_of = body.clone();
    for j in joints {
        let (a, c) = (root(&mut comp_of, j.right), root(&mut comp_of, j.left));
        comp_of[a] = c;
    }
    let comps = (0..rods).map(|i| root(&mut comp_of, i)).collect();
    (body, comps)
}

/// The bodies of a component's rods `members`, sorted: the unknowns `(t, ω)` of the `k`-th
/// are columns `6k..6k + 6`. Beyond [`MAX_GROUPS`], the whole component is one body (its
/// rods' `body` set so).
fn bodies_of(members: &[usize], body: &mut [usize]) -> Vec<usize> {
    let mut groups: Vec<usize> = members.iter().map(|&i| body[i]).collect();
    groups.sort_unstable();
    groups.dedup();
    if groups.len() > MAX_GROUPS {
        // one body: the motions of the whole component
        for &i in members {
            body[i] = groups[0];
        }
        groups.truncate(1);
    }
    groups
}

/// The Gram matrix `AᵀA` of the rows `A` of the check, summed row by row (a row has at most
/// twelve entries; a large assembly has millions of rows).
struct Gram(DMatrix<f64>);

impl Gram {
    /// Adds a sparse row, as (column, value) pairs.
    fn add(&mut self, row: &[(usize, f64)]) {
        for &(a, va) in row {
            for &(b, vb) in row {
                self.0[(a, b)] += va * vb;
            }
        }
    }
}

/// The row `d · (t + ω × x)` of the body whose unknowns begin at column `c`: the motion of
/// the point `x` along `d` (`x` and `ω` scaled by the length).
fn position_row(c: usize, d: Vector3<f64>, x: Vector3<f64>) -> Vec<(usize, f64)> {
    let xd = x.cross(&d); // d · (ω × x) = ω · (x × d)
    (0..3)
        .map(|k| (c + k, d[k]))
        .chain((0..3).map(|k| (c + 3 + k, xd[k])))
        .collect()
}

/// What the rows of the check are written from: the natural assembly, its supports and the
/// joints that tie its rods.
struct Supports<'a> {
    assembly: &'a Assembly,
    b: &'a BoundaryConditions,
    /// The pin joints, when active.
    joints: &'a [Joint],
    /// Length (m) positions are divided by.
    scale: f64,
    /// Whether the tip's height is held (displacement control).
    tip_height_held: bool,
}

impl Supports<'_> {
    /// The rows of what the base and the tip of every rod of `members` hold; `column` the
    /// first column of a rod's body.
    fn support_rows(&self, gram: &mut Gram, members: &[usize], column: &impl Fn(usize) -> usize) {
        let (assembly, b) = (self.assembly, self.b);
        for &i in members {
            let h = &assembly.rods[i];
            for (cond, s, z_held) in [
                (b.base, 0.0, true),
                (b.tip, assembly.length, self.tip_height_held),
            ] {
                let x = h.position(s) / self.scale;
                let c = column(i);
                if z_held {
                    gram.add(&position_row(c, Vector3::z(), x));
                }
                for d in held_directions(cond.translation, &x) {
                    gram.add(&position_row(c, d, x));
                }
                match cond.rotation {
                    Rotation::Clamped => (0..3).for_each(|k| gram.add(&[(c + 3 + k, 1.0)])),
                    Rotation::Pinned => gram.add(&[(c + 5, 1.0)]),
                    Rotation::Free => {}
                }
            }
        }
    }

    /// The rows of the joints of component `comp` between different bodies: the two rods'
    /// positions tied at the crossing (at an end, in the directions the support leaves free).
    fn joint_rows(
        &self,
        gram: &mut Gram,
        comp: usize,
        comps: &[usize],
        column: &impl Fn(usize) -> usize,
    ) {
        let (assembly, b) = (self.assembly, self.b);
        for j in self.joints {
            if comps[j.right] != comp || column(j.right) == column(j.left) {
                continue;
            }
            let x = assembly.rods[j.right].position(j.s) / self.scale;
            let dirs = if j.s <= 1e-9 * assembly.length {
                free_directions(b.base.translation, &x)
            } else if j.s >= assembly.length * (1.0 - 1e-9) {
                free_directions(b.tip.translation, &x)
            } else if b.joints.slides() {
                // the contact slides along both tangents: only the normal to both is tied
                let tangent = |rod: usize| assembly.rods[rod].directors(j.s).column(2).into_owned();
                let (tr, tl) = (tangent(j.right), tangent(j.left));
                vec![tr.cross(&tl).normalize()]
            } else {
                vec![Vector3::x(), Vector3::y(), Vector3::z()]
            };
            for d in dirs {
                let mut row = position_row(column(j.right), d, x);
                row.extend(
                    position_row(column(j.left), d, x)
                        .into_iter()
                        .map(|(c, v)| (c, -v)),
                );
                gram.add(&row);
            }
            let (cr, cl) = (column(j.right) + 3, column(j.left) + 3);
            for a in rotation_axes(self.b.joints, &x) {
                let row: Vec<(usize, f64)> = (0..3)
                    .map(|k| (cr + k, a[k]))
                    .chain((0..3).map(|k| (cl + k, -a[k])))
                    .collect();
                gram.add(&row);
            }
        }
    }
}

/// The axes about which a joint at `x` ties the rotations of its two rods: all three for a
/// weld, those with a spring for elastic joints (the normal to the tube's surface for the
/// scissor spring, the two axes in the surface for the others), none for a pin.
fn rotation_axes(joints: Joints, x: &Vector3<f64>) -> Vec<Vector3<f64>> {
    let radial = Vector3::new(x[0], x[1], 0.0);
    let n = if radial.norm() > 0.0 {
        radial / radial.norm()
    } else {
        Vector3::x()
    };
    let t = n.cross(&Vector3::z()).normalize();
    match joints {
        Joints::Welded => vec![Vector3::x(), Vector3::y(), Vector3::z()],
        Joints::Elastic(k) => {
            let mut axes = Vec::new();
            if k.scissor > 0.0 {
                axes.push(n);
            }
            if k.out_of_plane > 0.0 {
                axes.extend([t, n.cross(&t)]);
            }
            axes
        }
        Joints::Pin | Joints::None | Joints::Sliding => Vec::new(),
    }
}

/// The rod of `members` turning fastest in one of the free motions `free`: the rod, its
/// translation and its rotation (scaled); `None` when none turns.
fn fastest_turning(
    free: &[Vec<f64>],
    members: &[usize],
    column: &impl Fn(usize) -> usize,
) -> Option<(usize, Vector3<f64>, Vector3<f64>)> {
    let mut turning = None;
    let mut fastest = 0.0;
    for v in free {
        for &i in members {
            let c = column(i);
            let w = Vector3::new(v[c + 3], v[c + 4], v[c + 5]);
            if w.norm() > fastest {
                fastest = w.norm();
                turning = Some((i, Vector3::new(v[c], v[c + 1], v[c + 2]), w));
            }
        }
    }
    turning.filter(|_| fastest > 1e-6)
}

/// Directions an end at `x` is held in, besides z (as the solver's supports).
fn held_directions(t: Translation, x: &Vector3<f64>) -> Vec<Vector3<f64>> {
    let radial = Vector3::new(x[0], x[1], 0.0);
    match t {
        Translation::Fixed => vec![Vector3::x(), Vector3::y()],
        Translation::Slide => vec![],
        Translation::Radial if radial.norm() > 0.0 => {
            let er = radial / radial.norm();
            vec![Vector3::new(-er[1], er[0], 0.0)]
        }
        Translation::Radial => vec![Vector3::x(), Vector3::y()],
    }
}

/// In-plane directions an end at `x` is free in (as the solver's joints at the ends).
fn free_directions(t: Translation, x: &Vector3<f64>) -> Vec<Vector3<f64>> {
    let radial = Vector3::new(x[0], x[1], 0.0);
    match t {
        Translation::Fixed => vec![],
        Translation::Slide => vec![Vector3::x(), Vector3::y()],
        Translation::Radial if radial.norm() > 0.0 => vec![radial / radial.norm()],
        Translation::Radial => vec![],
    }
}

/// An orthonormal basis of the null space of `m`, whose entries are of order one or
/// less: its right singular vectors of singular value below [`RANK_TOL`] of the largest
/// or of one, whichever is larger.
fn null_space(m: &DMatrix<f64>) -> Vec<Vec<f64>> {
    null_space_of_gram(m.transpose() * m)
}

/// [`null_space`] of the matrix whose Gram matrix `mᵀm` is `gram`.
fn null_space_of_gram(gram: DMatrix<f64>) -> Vec<Vec<f64>> {
    let cols = gram.ncols();
    let eig = gram.symmetric_eigen();
    let largest = eig.eigenvalues.iter().cloned().fold(1.0f64, f64::max);
    (0..cols)
        .filter(|&k| eig.eigenvalues[k] <= RANK_TOL * RANK_TOL * largest)
        .map(|k| eig.eigenvectors.column(k).iter().cloned().collect())
        .collect()
}

/// A free motion that is a translation of every group (no rotation, one `t`), if the null
/// space `free` holds one: its direction.
fn translation_in(free: &[Vec<f64>], groups: usize) -> Option<Vector3<f64>> {
    // combinations c of the basis with every rotation zero and every group's translation
    // that of the first: the null space of those rows applied to the basis
    let d = free.len();
    let mut rows = DMatrix::<f64>::zeros(6 * groups, d);
    for (k, f) in free.iter().enumerate() {
        for g in 0..groups {
            for i in 0..3 {
                rows[(6 * g + i, k)] = f[6 * g + 3 + i];
                rows[(6 * g + 3 + i, k)] = f[6 * g + i] - f[i];
            }
        }
    }
    let c = null_space(&rows).into_iter().next()?;
    let t: Vector3<f64> = (0..d)
        .map(|k| Vector3::new(free[k][0], free[k][1], free[k][2]) * c[k])
        .sum();
    (t.norm() > 1e-6).then(|| t / t.norm())
}

/// A free motion found on a component of the assembly, as [`describe`] says it.
struct Found<'a> {
    assembly: &'a Assembly,
    /// Length (m) positions were divided by.
    scale: f64,
    /// Helices of the assembly.
    n: usize,
    /// The component is one rod (no joint ties it to the others).
    one_rod: bool,
    /// The direction of a translation of the whole component, if one is free.
    translation: Option<Vector3<f64>>,
    /// Otherwise the rod turning fastest, with its translation and rotation (scaled).
    turning: Option<(usize, Vector3<f64>, Vector3<f64>)>,
}

/// The free motion in the user's terms: what moves, how, and what to change.
fn describe(b: &BoundaryConditions, found: &Found) -> FreeMotion {
    let who = if found.n == 1 {
        "the rod"
    } else if found.one_rod {
        "each rod (no joint ties it to the others)"
    } else {
        "the assembly"
    };
    if let Some(d) = found.translation {
        return FreeMotion {
            half: "translation",
            message: translation_message(b, who, d),
        };
    }
    let Some((rod, t, w)) = found.turning else {
        // rods translating relative to one another
        return FreeMotion {
            half: "translation",
            message: format!(
                "the joints leave the rods of {who} free to slide relative to one another (a free rigid motion of each); fix the translation of one end"
            ),
        };
    };
    // a rotation, of unit rate
    let (t, w) = (t / w.norm(), w / w.norm());
    let h = &found.assembly.rods[rod];
    let moves = |s: f64| (t + w.cross(&(h.position(s) / found.scale))).norm() > 1e-6;
    let (base_moves, tip_moves) = (moves(0.0), moves(found.assembly.length));
    let message = if !base_moves
        && !tip_moves
        && b.base.rotation == Rotation::Free
        && b.tip.rotation == Rotation::Free
    {
        chord_message(found)
    } else {
        rotation_message(b, who, w, (base_moves, tip_moves))
    };
    FreeMotion {
        half: "rotation",
        message,
    }
}

/// A sideways translation along `d` of `who`, and the ends that let it.
fn translation_message(b: &BoundaryConditions, who: &str, d: Vector3<f64>) -> String {
    let slides = |e: EndCondition| e.translation == Translation::Slide;
    let radial = |e: EndCondition| e.translation == Translation::Radial;
    let ends = match (b.base.translation, b.tip.translation) {
        (Translation::Slide, Translation::Slide) => "both ends slide".to_string(),
        _ if radial(b.base) && radial(b.tip) => {
            "both ends slide radially (translation = \"radial\") along parallel radii".into()
        }
        _ => format!(
            "the {} slides and the {} slides radially (translation = \"radial\")",
            if slides(b.base) { "base" } else { "tip" },
            if slides(b.base) { "tip" } else { "base" }
        ),
    };
    format!(
        "{ends}: {who} may translate sideways as a whole, along ({:.3}, {:.3}, 0) (a free rigid motion); fix the translation of one end",
        tidy(d[0]),
        tidy(d[1])
    )
}

/// A turn about the chord between two spherical hinges.
fn chord_message(found: &Found) -> String {
    let who = if found.one_rod {
        if found.n == 1 {
            "the rod may turn about its chord, the line from base to tip"
        } else {
            "each rod may turn about its chord, the line from base to tip"
        }
    } else {
        "the assembly may turn as a whole about its chord, the line from base to tip through the points where its rods meet"
    };
    format!(
        "both ends are spherical hinges (rotation = \"free\"): {who} (a free rigid motion); clamp or pin one end"
    )
}

/// A turn of `who` about the axis `w` (unit), the ends that move in it (`(base, tip)`)
/// and how they move, and what to change.
fn rotation_message(
    b: &BoundaryConditions,
    who: &str,
    w: Vector3<f64>,
    (base_moves, tip_moves): (bool, bool),
) -> String {
    let axis = if w[0].hypot(w[1]) < 1e-6 {
        "a vertical axis".to_string()
    } else if w[2].abs() < 1e-6 {
        "a horizontal axis".to_string()
    } else {
        format!(
            "an axis along ({:.3}, {:.3}, {:.3})",
            tidy(w[0]),
            tidy(w[1]),
            tidy(w[2])
        )
    };
    let ends = [(b.base, "base", base_moves), (b.tip, "tip", tip_moves)]
        .iter()
        .filter(|(_, _, m)| *m)
        .map(|(e, name, _)| {
            let how = match e.translation {
                Translation::Slide => "sliding",
                Translation::Radial => "sliding radially",
                Translation::Fixed => "rising (its height is free under load control)",
            };
            format!("its {name} {how}")
        })
        .collect::<Vec<_>>();
    let fix = match (b.base.rotation, b.tip.rotation) {
        (Rotation::Free, Rotation::Free) => "clamp or pin one end",
        _ => "clamp one end",
    };
    format!(
        "the supports (base {}, tip {}) leave {who} free to turn about {axis}{} (a free rigid motion); {fix}{}",
        b.base.label(),
        b.tip.label(),
        if ends.is_empty() {
            String::new()
        } else {
            format!(", {}", ends.join(" and "))
        },
        if ends.iter().any(|e| e.contains("slid")) {
            ", or fix the translation of the sliding end"
        } else {
            ""
        }
    )
}

/// A component of a unit vector for a message with three decimals: no `-0.000`.
fn tidy(v: f64) -> f64 {
    if v.abs() < 5e-4 {
        0.0
    } else {
        v
    }
}
