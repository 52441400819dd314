//! What a solve reports, as plain data: load points along the path, the shape of a state,
//! its stability and the critical points found. The solver fills these in; outputs and
//! screens read them. Nothing here computes beyond a mean of what a value holds.

use crate::model::assembly::RodId;
use crate::model::helix::Chirality;
use crate::model::loading::{Component, Control};

/// Force (N) and moment (N m) applied by a support to a rod end, global frame.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Reaction {
    pub force: [f64; 3],
    pub moment: [f64; 3],
}

/// The reactions on one rod.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RodReaction {
    pub rod: RodId,
    pub chirality: Chirality,
    pub tip: Reaction,
    pub base: Reaction,
}

/// One converged point of the load path.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadPoint {
    /// Output step number (0 for the natural state).
    pub step: usize,
    /// Compression ratio `ε = (h0 − h)/h0` (negative in extension), from the mean tip height.
    pub compression_ratio: f64,
    /// Load parameter: `ε` under displacement control, `P/Pcrit` under load control.
    pub parameter: f64,
    /// Tip height `h` (m).
    pub height: f64,
    pub reactions: Vec<RodReaction>,
    /// `(1/(n Pcrit)) Σ_rods F_tip` per component (negative z = compression).
    pub load: [f64; 3],
    /// Total elastic energy (J).
    pub energy: f64,
    /// Newton iterations of the last solve that reached this point.
    pub iterations: usize,
    /// `‖R‖∞` at this point.
    pub residual: f64,
    /// Stability of the state, when tracked.
    pub stability: Option<Stability>,
    /// The tube's answer to its twist, tilt and pressure.
    pub support: SupportResponse,
}

impl SupportResponse {
    /// The displacement of `component` and its conjugate force, with their names and
    /// units for a table's head: `(φ, T)`, `(θ, M)`, `(radius, q)`; `None` for the axial
    /// component, whose pair is the load point's compression ratio and load.
    pub fn pair(&self, component: Component) -> Option<[(f64, &'static str); 2]> {
        match component {
            Component::Axial => None,
            Component::Twist => Some([(self.twist, "phi (rad)"), (self.torque, "T (N m)")]),
            Component::Tilt => Some([(self.tilt, "theta (rad)"), (self.bending_moment, "M (N m)")]),
            Component::Pressure => Some([(self.radius, "radius (m)"), (self.pressure, "q (N/m)")]),
        }
    }
}

/// Each load component's displacement beside its conjugate force, for the whole assembly
/// (the axial pair is [`LoadPoint`]'s `compression_ratio` and `load`): the work of the
/// supports is `∫ torque dφ + ∫ bending_moment dθ − n L ∫ pressure d(radius)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SupportResponse {
    /// Twist `φ` of the tip support about the tube's axis (rad).
    pub twist: f64,
    /// Torque about the axis that the tip support applies to the rods (N m), summed.
    pub torque: f64,
    /// Tilt `θ` of the tip support about the x axis through the tip's centre (rad).
    pub tilt: f64,
    /// Bending moment about that axis that the tip support applies to the rods (N m).
    pub bending_moment: f64,
    /// Radial line pressure `q` on every rod (N/m, inward positive).
    pub pressure: f64,
    /// The rods' mean distance from the axis, `(1/(n L)) Σ ∫ ρ ds` (m).
    pub radius: f64,
    /// The pressure on the tube's lateral surface that the line pressure amounts to,
    /// `n q L / (2π radius h)` (Pa): the total radial force over the cylinder's area.
    pub lateral_pressure: f64,
    /// The unit of the normalised moments, `B1/L` (N m).
    pub unit_moment: f64,
}

/// One quaternion node of a rod in a state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeState {
    /// Arc length `s` (m).
    pub s: f64,
    /// `s / L`.
    pub s_over_l: f64,
    /// Centreline position (m).
    pub position: [f64; 3],
    /// Unit quaternion `(q1, q2, q3, q4)`.
    pub quaternion: [f64; 4],
    /// `(κ1, κ2, Ω)` (1/m), recovered from the Barlow points of the elements around the node
    /// by a local least-squares fit (`discretisation::fields::recovered_curvature`).
    pub curvature: [f64; 3],
    /// Internal force `n` (N, global frame): the force the part of the rod beyond `s`
    /// exerts on the part before it, constant along an element (the multiplier of its
    /// inextensibility constraint); at an element vertex the mean of the two elements
    /// meeting there (it jumps at a pin joint by the joint's force).
    pub internal_force: [f64; 3],
}

/// The shape of one rod.
#[derive(Clone, Debug, PartialEq)]
pub struct RodShape {
    pub rod: RodId,
    pub chirality: Chirality,
    pub nodes: Vec<NodeState>,
    /// Arc lengths of its active joints (m).
    pub joints: Vec<f64>,
    /// What each of its active joints carries, in the order of `joints`.
    pub joint_states: Vec<JointState>,
}

/// A joint as one of the rods it ties sees it in a state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JointState {
    /// Arc length of the crossing (m).
    pub s: f64,
    /// Rotation (rad) of the left rod's frame relative to the right rod's, from its natural
    /// value, in the right rod's frame on the axes (normal to the tube's surface, the right
    /// rod's natural tangent, their cross product): `2 vec(q̄_R ∘ q_L ∘ q̄_0)`; its first
    /// component is the change of the scissor angle.
    pub rotation: [f64; 3],
    /// Moment (N m, global frame) the joint applies to this rod (zero for a pin).
    pub moment: [f64; 3],
    /// The rod's internal moment (N m, global frame: the moment the part beyond exerts on
    /// the part before) just before and just after the crossing; at a rod end the missing
    /// side is zero. `moment_after − moment_before + moment = 0` is the balance of the node.
    pub moment_before: [f64; 3],
    pub moment_after: [f64; 3],
    /// Slip (m) of a sliding joint's contact along this rod, `s_contact − s` (zero for the
    /// other kinds).
    pub slip: f64,
}

/// The shape of every rod in a state.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    /// Compression ratio `ε` of the state.
    pub compression_ratio: f64,
    pub rods: Vec<RodShape>,
}

impl Snapshot {
    /// The horizontal offset (m, x and y) of the centre of the rods' tip ends from the
    /// centre of their base ends (each the mean over the rods). Its change from the natural
    /// state is the sway of the tip: none to rounding on a path that keeps the assembly's
    /// rotational symmetry, what tells a sway branch from the fundamental path when the
    /// tip slides free of lateral forces.
    pub fn tip_offset(&self) -> [f64; 2] {
        let centre = |end: fn(&RodShape) -> Option<&NodeState>| {
            let ends: Vec<[f64; 3]> = self
                .rods
                .iter()
                .filter_map(end)
                .map(|n| n.position)
                .collect();
            let n = ends.len().max(1) as f64;
            [0, 1].map(|k| ends.iter().map(|p| p[k]).sum::<f64>() / n)
        };
        let (base, tip) = (centre(|r| r.nodes.first()), centre(|r| r.nodes.last()));
        [tip[0] - base[0], tip[1] - base[1]]
    }
}

/// A critical mode's centreline displacement at one element vertex of a rod (m per unit
/// mode): a row of `mode-<k>.csv`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeVertex {
    pub rod: usize,
    /// Arc length of the vertex (m), and over the rod's length.
    pub s: f64,
    pub s_over_l: f64,
    pub displacement: [f64; 3],
}

/// Stability of a converged state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stability {
    /// Negative eigenvalues of the Hessian of the Lagrangian on the tangent space of the
    /// constraints (0: stable).
    pub unstable_directions: usize,
    /// Lowest eigenvalue of that Hessian in the metric of nodal rotations weighted by
    /// arc length (J/m; negative when unstable), where computed.
    pub lowest_eigenvalue: Option<f64>,
    /// Circumferential wavenumber of the lowest eigenvalue's mode, for an assembly judged
    /// by its Bloch blocks (docs/theory.md §7); `None` otherwise.
    pub lowest_wavenumber: Option<usize>,
}

impl Stability {
    pub fn is_stable(&self) -> bool {
        self.unstable_directions == 0
    }
}

/// Kind of a critical point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CriticalKind {
    /// A fold of the path in the load parameter.
    LimitPoint,
    /// Another branch crosses the path.
    Bifurcation,
    /// A neutral direction: an eigenvalue zero to rounding along the path, not a crossing
    /// (a buckled isotropic rod turning about its axis). Recorded once, where the count
    /// of unstable directions first flipped on it; it counts as stable.
    Neutral,
}

impl CriticalKind {
    pub fn name(self) -> &'static str {
        match self {
            CriticalKind::LimitPoint => "limit-point",
            CriticalKind::Bifurcation => "bifurcation",
            CriticalKind::Neutral => "neutral",
        }
    }
}

/// A critical point located on the path.
#[derive(Clone, Debug, PartialEq)]
pub struct CriticalPoint {
    pub kind: CriticalKind,
    pub control: Control,
    /// Load parameter at the critical point.
    pub parameter: f64,
    /// Compression ratio there.
    pub compression_ratio: f64,
    /// `(1/(n Pcrit)) Σ F_tip` there.
    pub load: [f64; 3],
    pub unstable_before: usize,
    pub unstable_after: usize,
    /// Circumferential wavenumber `p` of the critical mode, for an assembly judged by its
    /// Bloch blocks (docs/theory.md §7): the mode repeats with phase `2πp/m` from one sector to
    /// the next (`p = 0`: the mode keeps the symmetry). `None` for the full model.
    pub wavenumber: Option<usize>,
    /// Axial Bloch phase `k` (rad per cell) of the critical mode, for the cell of an
    /// infinite tube judged by its blocks `H(p, k)` (docs/theory.md §8); `None` otherwise.
    pub bloch_phase: Option<f64>,
    /// How many independent modes cross zero together: 2 for `0 < p < m/2` (the modes of
    /// `p` and `m − p`), 1 otherwise.
    pub multiplicity: usize,
    /// State at the critical point (all unknowns of the model solved).
    pub state: Vec<f64>,
    /// Critical mode: the near-null vector of the KKT matrix there (all unknowns of the
    /// model solved), scaled to unit norm over the primal unknowns.
    pub mode: Vec<f64>,
    /// For a symmetric pair: the critical mode on the whole assembly (the primal unknowns of
    /// the full model, unit norm), rebuilt from its Bloch block's eigenvector.
    pub assembly_mode: Option<Vec<f64>>,
    /// For a double point (`0 < p < m/2`): the other mode of its plane (from `i` times the
    /// block's eigenvector); every critical mode there is `cos φ · assembly_mode + sin φ ·
    /// second_mode`. For a double point of a model judged on itself (count change 2): the
    /// other mode nearest zero, orthogonal to `mode` in the eigenproblem's metric (then
    /// every critical mode is `cos φ · mode + sin φ · second_mode`).
    pub second_mode: Option<Vec<f64>>,
}

impl CriticalPoint {
    /// The change of the count of unstable directions as the faces show it, `arrow`
    /// between the counts either side (`0 → 1`); a neutral direction, which crosses nothing
    /// and counts as stable, as the count it keeps and the word `neutral` (`0, neutral`).
    pub fn count_change(&self, arrow: &str) -> String {
        match self.kind {
            CriticalKind::Neutral => {
                format!("{}, neutral", self.unstable_before.min(self.unstable_after))
            }
            _ => format!("{} {arrow} {}", self.unstable_before, self.unstable_after),
        }
    }
}

/// The bulk of one rod in a state: the longest stretch of arc length where its curvatures
/// stay within a tolerance of one uniform helix (thesis §4, "bulk" and boundary layers),
/// the helix fitted there, the axial force and couple Love's closed form gives for that
/// helix (docs/theory.md §6), and the rod's actual tip reactions beside them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RodBulk {
    pub rod: RodId,
    pub chirality: Chirality,
    /// Rod length `L` (m).
    pub length: f64,
    /// Arc lengths where the bulk starts and ends (m); the boundary layers are `[0, start]`
    /// and `[end, L]`.
    pub start: f64,
    pub end: f64,
    /// Mean curvatures `(κ1, κ2, Ω)` over the bulk (1/m).
    pub curvature: [f64; 3],
    /// Radius `a` and pitch parameter `b` of the fitted helix (m): `a = K/(K² + Ω²)`,
    /// `b = χ Ω/(K² + Ω²)`, `K = √(κ1² + κ2²)` (negative `b`: the bulk turned the other way).
    pub radius: f64,
    pub pitch: f64,
    /// Love's axial force on the tip (N, tension positive) and axial couple (N m) for the
    /// fitted helix; `None` where the helix is degenerate (straight, or a naturally straight
    /// rod).
    pub love_force: Option<f64>,
    pub love_moment: Option<f64>,
    /// The rod's tip reaction: axial force `Fz` (N) and couple about the tube axis
    /// `Mz + (r_tip × F)_z` (N m), the quantities Love's are.
    pub axial_force: f64,
    pub axial_moment: f64,
}

impl RodBulk {
    /// `start / L`.
    pub fn start_over_l(&self) -> f64 {
        self.start / self.length
    }
    /// `end / L`.
    pub fn end_over_l(&self) -> f64 {
        self.end / self.length
    }
}

/// The bulk of every rod at one output step, with the infinitely long tube beside the
/// finite assembly.
#[derive(Clone, Debug, PartialEq)]
pub struct StepBulk {
    pub step: usize,
    /// Compression ratio `ε` of the step.
    pub compression_ratio: f64,
    pub rods: Vec<RodBulk>,
    /// Axial force per rod of the infinite tube at this `ε` (N): Love's on the helix of the
    /// same arc length per turn, `c = c0`, `b = b0 (1 − ε)` (docs/theory.md §7); `None` for
    /// naturally straight rods.
    pub tube_force: Option<f64>,
    /// The finite assembly's mean tip `Fz` over its rods divided by `tube_force`; `None` at
    /// `ε = 0` (both vanish).
    pub tube_ratio: Option<f64>,
    /// Under a radial pressure: the bulk radius of the infinite tube that the pressure holds
    /// with no axial force (m), the pantograph's closed form (docs/loads.md); `None` without
    /// pressure, for other elastic hypotheses, or past the largest pressure it carries.
    pub tube_radius: Option<f64>,
    /// The rods' mean fitted bulk radius over `tube_radius`.
    pub radius_ratio: Option<f64>,
}

/// A critical mode on the geometry of its state, for output: the shape of the state at the
/// critical point (the model's own rods) and the mode's centreline displacement at every
/// quaternion node of each (m per unit mode).
#[derive(Clone, Debug, PartialEq)]
pub struct ModeShape {
    pub shape: Snapshot,
    pub displacement: Vec<Vec<[f64; 3]>>,
}
