//! Meshes of the rods: element vertices placed at every joint's arc length.

use super::shape::Order;

/// The mesh of one rod of length `L`: element vertices `0 = s_0 < s_1 < … < s_ne = L`.
#[derive(Clone, Debug, PartialEq)]
pub struct RodMesh {
    /// Arc lengths of the element vertices (m).
    pub vertices: Vec<f64>,
    pub order: Order,
}

impl RodMesh {
    /// About `elements` elements on `[0, length]`, with a vertex at every breakpoint
    /// (joints): each interval between breakpoints gets `⌈elements · len / L⌉` equal
    /// elements, so the total is at least `elements` (more when joints split the rod
    /// into intervals that do not divide it evenly).
    pub fn new(length: f64, elements: usize, order: Order, breakpoints: &[f64]) -> RodMesh {
        let tol = 1e-9 * length;
        let mut cuts: Vec<f64> = vec![0.0];
        for &b in breakpoints {
            if b > tol && b < length - tol {
                cuts.push(b);
            }
        }
        cuts.push(length);
        cuts.sort_by(f64::total_cmp);
        cuts.dedup_by(|a, b| (*a - *b).abs() <= tol);
        let mut vertices = vec![0.0];
        for w in cuts.windows(2) {
            let len = w[1] - w[0];
            let k = ((elements as f64 * len / length - 1e-9).ceil() as usize).max(1);
            for i in 1..=k {
                vertices.push(if i == k {
                    w[1]
                } else {
                    w[0] + len * i as f64 / k as f64
                });
            }
        }
        RodMesh { vertices, order }
    }

    pub fn elements(&self) -> usize {
        self.vertices.len() - 1
    }

    /// Number of quaternion nodes, `p · elements + 1`.
    pub fn quaternion_nodes(&self) -> usize {
        self.order.degree() * self.elements() + 1
    }

    /// Arc length of quaternion node `k` (m).
    pub fn node_arc_length(&self, k: usize) -> f64 {
        let p = self.order.degree();
        let (e, a) = (k / p, k % p);
        if e == self.elements() {
            return self.vertices[e];
        }
        let (s0, s1) = (self.vertices[e], self.vertices[e + 1]);
        s0 + (s1 - s0) * a as f64 / p as f64
    }

    /// Index of the vertex at arc length `s`, if there is one.
    pub fn vertex_at(&self, s: f64) -> Option<usize> {
        let tol = 1e-9 * self.vertices[self.elements()];
        self.vertices.iter().position(|&v| (v - s).abs() <= tol)
    }
}
