//! `joints.csv`: where the joints are, and what they carry in a state.

use super::csv::{format, table};
use crate::results::Snapshot;
use serde::Serialize;

/// A row of `joints.csv`: one joint on one rod.
#[derive(Serialize, Default)]
struct JointRow {
    rod: usize,
    /// Arc length of the joint on the rod (m).
    #[serde(serialize_with = "format::e10")]
    s: f64,
    #[serde(serialize_with = "format::e10")]
    s_over_l: f64,
    #[serde(serialize_with = "format::e10")]
    rot_n: f64,
    #[serde(serialize_with = "format::e10")]
    rot_t: f64,
    #[serde(serialize_with = "format::e10")]
    rot_b: f64,
    #[serde(serialize_with = "format::e10")]
    mx: f64,
    #[serde(serialize_with = "format::e10")]
    my: f64,
    #[serde(serialize_with = "format::e10")]
    mz: f64,
    #[serde(serialize_with = "format::e10")]
    rod_mx_before: f64,
    #[serde(serialize_with = "format::e10")]
    rod_my_before: f64,
    #[serde(serialize_with = "format::e10")]
    rod_mz_before: f64,
    #[serde(serialize_with = "format::e10")]
    rod_mx_after: f64,
    #[serde(serialize_with = "format::e10")]
    rod_my_after: f64,
    #[serde(serialize_with = "format::e10")]
    rod_mz_after: f64,
    #[serde(serialize_with = "format::e10")]
    slip: f64,
}

/// `joints.csv`: the active joints of every rod (a joint ties two rods, so it has a row on
/// each), as the library reports them in [`Snapshot`]: where they are (fixed material
/// points), and the relative rotation and moments in the snapshot's state (the run's last).
pub fn joints_csv(case: &str, snapshot: &Snapshot) -> String {
    let comments = [
        format!(
            "spira joints, case {case}, state at eps = {}",
            snapshot.compression_ratio
        ),
        "s: arc length of the joint on the rod (m), one row per rod it ties; s_over_l: s/L; \
         rot_n,rot_t,rot_b: rotation of the left rod's frame relative to the right rod's from \
         its natural value (rad), in the right rod's frame about the normal to the tube's \
         surface (the change of the scissor angle), the right rod's tangent and their cross \
         product; mx,my,mz: moment the joint applies to the rod (N m, zero for a pin); \
         rod_mx_before,rod_my_before,rod_mz_before,rod_mx_after,rod_my_after,rod_mz_after: \
         the rod's internal moment just before and just after the crossing (N m, zero beyond \
         an end), so that after - before + joint moment = 0; slip: how far a sliding joint's \
         contact has slid along the rod from s (m, zero for the other kinds)"
            .to_string(),
    ];
    let length = snapshot
        .rods
        .iter()
        .filter_map(|r| r.nodes.last())
        .map(|n| n.s / n.s_over_l)
        .find(|l| l.is_finite())
        .unwrap_or(1.0);
    let rows = snapshot.rods.iter().flat_map(|rod| {
        rod.joints.iter().enumerate().map(move |(k, &s)| {
            let j = rod.joint_states.get(k).copied().unwrap_or_default();
            JointRow {
                rod: rod.rod,
                s,
                s_over_l: s / length,
                rot_n: j.rotation[0],
                rot_t: j.rotation[1],
                rot_b: j.rotation[2],
                mx: j.moment[0],
                my: j.moment[1],
                mz: j.moment[2],
                rod_mx_before: j.moment_before[0],
                rod_my_before: j.moment_before[1],
                rod_mz_before: j.moment_before[2],
                rod_mx_after: j.moment_after[0],
                rod_my_after: j.moment_after[1],
                rod_mz_after: j.moment_after[2],
                slip: j.slip,
            }
        })
    });
    table(&comments, rows)
}
