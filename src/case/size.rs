//! The size of a case's problem, estimated from its mesh before anything is built: the
//! unknowns of the KKT system, the nonzeros of its matrix and the memory of its
//! factorisations, against the memory of the machine.

use super::limits::{estimated_joints, num};
use super::settings::{Discretisation, Geometry};
use crate::discretisation::shape::Order;
use std::fmt;

/// Cases of more unknowns than this print their size before solving.
pub const LARGE_UNKNOWNS: f64 = 50_000.0;

/// Cases whose stability checks are estimated to take longer than this per load step
/// (s) print their size before solving.
pub const LONG_STEP_SECONDS: f64 = 10.0;

/// Seconds per factorised entry of the Bloch blocks in one load step (its stability
/// checks, the critical-point search and the lowest eigenvalue's iterations included),
/// fitted on this 2-core machine to symmetric pairs of thesis assemblies of n = 16, 32, 64
/// and 128 helices (4 steps to ε = 0.05 took 1.1, 2.6, 7.8, 24 s, 3.7e-8 to 1.5e-8 s per
/// estimated entry, falling as the blocks take over from the fixed cost of a step): an
/// upper value where the blocks dominate.
const SECONDS_PER_BLOCK_ENTRY: f64 = 2e-8;

/// An estimate of the size of a case's problem: upper bounds, within a factor of about 2
/// of the unknowns and the peak memory measured on the full models of thesis assemblies of
/// 8 to 32 helices (pairs, 56 elements: 19, 23, 38, 68 MB measured for n = 8, 16, 32, 64
/// against 51, 71, 124, 231 MB estimated).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SizeEstimate {
    /// Rods solved (a symmetric pair: 2).
    pub rods: f64,
    /// Elements per rod, joints' vertices included.
    pub elements_per_rod: f64,
    /// Pin joints of the solved rods.
    pub joints: f64,
    /// Unknowns of the KKT system, multipliers included.
    pub unknowns: f64,
    /// Nonzeros of the KKT matrix.
    pub nonzeros: f64,
    /// Entries of one sparse factorisation (LU, or the LDLᵀ of the stability count).
    pub factor_entries: f64,
    /// Bloch blocks factorised per stability check: `⌊m/2⌋ + 1` for a symmetric pair of
    /// `n = 2m` rods (wavenumbers `p = 0 ..= m/2`), 0 for the full model, whose stability
    /// is the LDLᵀ already counted.
    pub blocks: f64,
    /// Work of the factorisations of all Bloch blocks of one stability check, in entries of
    /// a real factor: the real blocks (`p = 0`, and `p = m/2` for even `m`) as large as the
    /// pair's LDLᵀ, the complex ones of the same pattern with complex entries (`LDLᴴ`),
    /// each complex product four real ones.
    pub block_entries: f64,
    /// The key that sets the size most directly.
    pub key: &'static str,
}

impl SizeEstimate {
    /// The estimate for `case` (floating point throughout, so that it cannot overflow).
    pub fn of(g: &Geometry, discretisation: &Discretisation) -> SizeEstimate {
        let n = g.helices as f64;
        let joints_all = estimated_joints(g);
        let joints_per_rod = if g.helices >= 2 {
            joints_all / (n / 2.0)
        } else {
            0.0
        };
        let rods = if discretisation.symmetric { 2.0 } else { n };
        let joints = joints_all * rods / n;
        // every interval between joints gets at least one element, and the `elements`
        // are shared out over the intervals (rounded up)
        let asked = discretisation.elements as f64;
        let elements = asked.max(joints_per_rod) + 0.5 * asked.min(joints_per_rod) + 1.0;
        let p = match discretisation.order {
            Order::Linear => 1.0,
            Order::Quadratic => 2.0,
        };
        // per element: p quaternion nodes (4 + 1 unit-norm multiplier each), a vertex (3)
        // and the inextensibility multiplier (3)
        let per_element = 5.0 * p + 6.0;
        let unknowns = rods * (per_element * elements + 8.0 + 12.0) + 6.0 * joints;
        // an element couples its p + 1 nodes and 2 vertices and its multiplier
        let block = 4.0 * (p + 1.0) + 6.0;
        let nonzeros = rods * elements * (block * block + 6.0 * block + 8.0 * p) + 36.0 * joints;
        // fill of the factors: a band of a few elements along each rod, plus a front across
        // the tube that grows with the rods the joints tie together
        // (fitted to the peak memory of thesis assemblies of n = 8, 16 and 32 helices:
        // 46, 122 and 675 MB for 7652, 15976 and 63312 unknowns, within a factor 2.2 above)
        let front = per_element * (8.0 + if g.helices >= 2 { 0.5 * rods } else { 0.0 });
        let factor_entries = unknowns * front;
        // the Bloch blocks of a pair, judged two at a time (two threads)
        let (blocks, block_entries) = if discretisation.symmetric && g.helices >= 4 {
            let m = (g.helices / 2) as f64;
            let blocks = (m / 2.0).floor() + 1.0;
            let real = if g.helices % 4 == 0 { 2.0 } else { 1.0 };
            let complex = (blocks - real).max(0.0);
            (blocks, (real + 4.0 * complex) * factor_entries)
        } else {
            (0.0, 0.0)
        };
        let key = if g.helices >= 16 && joints_per_rod > discretisation.elements as f64 {
            "geometry.helices"
        } else {
            "discretisation.elements"
        };
        SizeEstimate {
            rods,
            elements_per_rod: elements,
            joints,
            unknowns,
            nonzeros,
            factor_entries,
            blocks,
            block_entries,
            key,
        }
    }

    /// Estimated time (s) of the stability checks of one load step: the Bloch blocks'
    /// factorisations of a symmetric pair (0 for the full model, whose cost the unknowns
    /// say).
    pub fn block_seconds_per_step(&self) -> f64 {
        SECONDS_PER_BLOCK_ENTRY * self.block_entries
    }

    /// Memory of a solve (bytes): the matrix, two factorisations (the Newton LU and the
    /// LDLᵀ of the stability count; Newton's own LDLᵀ, of the stability's pattern, fits in
    /// the margin: full thesis models of n = 8 and 16, 56 elements, measured 48 and 141 MB
    /// against 73 and 264 MB estimated) at a value and an index each, and the state vectors;
    /// for a symmetric pair also the block factorisations held at once (two threads, each
    /// with a real and a complex one of the pair's pattern: 8 + 16 bytes an entry, and the
    /// entries' working copies) and the warm start of every block's eigenvalue iteration
    /// (a complex vector each).
    pub fn memory_bytes(&self) -> f64 {
        let blocks = if self.blocks > 0.0 {
            2.0 * 2.0 * 24.0 * self.factor_entries + self.blocks * 16.0 * self.unknowns
        } else {
            0.0
        };
        16.0 * self.nonzeros
            + 2.0 * 16.0 * self.factor_entries
            + 8.0 * 40.0 * self.unknowns
            + blocks
    }

    /// Whether the case is long enough to say its size before solving: many unknowns, or
    /// stability checks of many Bloch blocks.
    pub fn is_large(&self) -> bool {
        self.unknowns > LARGE_UNKNOWNS || self.block_seconds_per_step() > LONG_STEP_SECONDS
    }

    /// Refuses a problem whose memory exceeds `available` bytes (when known).
    pub fn check_fits(&self, available: Option<f64>) -> Result<(), TooLarge> {
        match available {
            Some(a) if self.memory_bytes() > a => Err(TooLarge {
                estimate: *self,
                available: a,
            }),
            _ => Ok(()),
        }
    }
}

impl fmt::Display for SizeEstimate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} rods of about {} elements, {} joints: about {} unknowns, {} nonzeros, {} per factorisation",
            self.rods,
            num(self.elements_per_rod.round()),
            num(self.joints.round()),
            num(self.unknowns.round()),
            num(self.nonzeros.round()),
            entries(self.factor_entries),
        )?;
        if self.blocks > 0.0 {
            write!(
                f,
                ", stability by {} Bloch blocks per check ({} factorised, about {} per load step)",
                num(self.blocks),
                entries(self.block_entries),
                seconds(self.block_seconds_per_step())
            )?;
        }
        write!(f, ", memory about {}", bytes(self.memory_bytes()))
    }
}

/// A problem that would not fit in memory.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("the case would need about {} of memory, {} are available ({estimate}); reduce `{}`", bytes(self.estimate.memory_bytes()), bytes(*available), estimate.key)]
pub struct TooLarge {
    pub estimate: SizeEstimate,
    /// Bytes available.
    pub available: f64,
}

/// A duration in s, min or h.
fn seconds(t: f64) -> String {
    if t < 120.0 {
        format!("{t:.1} s")
    } else if t < 7200.0 {
        format!("{:.0} min", t / 60.0)
    } else {
        format!("{} h", num((t / 3600.0).round()))
    }
}

fn entries(x: f64) -> String {
    format!("{} entries", num(x.round()))
}

/// Bytes in KB, MB, GB, TB.
fn bytes(b: f64) -> String {
    let units = ["B", "KB", "MB", "GB", "TB", "PB", "EB"];
    let mut v = b;
    let mut k = 0;
    while v >= 1000.0 && k + 1 < units.len() {
        v /= 1000.0;
        k += 1;
    }
    if v >= 1000.0 {
        return format!("{} B", num(b));
    }
    format!("{v:.1} {}", units[k])
}

/// Memory the machine can give a new solve (bytes): `MemAvailable` of `/proc/meminfo` on
/// Linux, else unknown.
pub fn available_memory() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}
