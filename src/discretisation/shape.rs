//! Shape functions and quadrature of the quaternion elements: Lagrange interpolation of order
//! `p` on equally spaced nodes, the one table of Gauss–Legendre rules, and the interpolation of
//! `q` and `q'` at a point of an element.

/// Largest number of quaternion nodes of an element (quadratic elements).
pub const MAX_NODES: usize = 3;

/// Polynomial order of the quaternion interpolation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Order {
    Linear,
    Quadratic,
}

impl Order {
    /// Polynomial degree `p`.
    pub fn degree(self) -> usize {
        match self {
            Order::Linear => 1,
            Order::Quadratic => 2,
        }
    }
    /// Quaternion nodes per element, `p + 1`.
    pub fn nodes(self) -> usize {
        self.degree() + 1
    }
    /// Name in tables, charts and case files.
    pub fn name(self) -> &'static str {
        match self {
            Order::Linear => "linear",
            Order::Quadratic => "quadratic",
        }
    }
}

/// Gauss–Legendre abscissae and weights on `[−1, 1]`: 2 points (exact to degree 3) and
/// 3 points (exact to degree 5).
pub const GAUSS_2: [(f64, f64); 2] = [
    (-0.577_350_269_189_625_8, 1.0),
    (0.577_350_269_189_625_8, 1.0),
];
pub const GAUSS_3: [(f64, f64); 3] = [
    (-0.774_596_669_241_483_4, 5.0 / 9.0),
    (0.0, 8.0 / 9.0),
    (0.774_596_669_241_483_4, 5.0 / 9.0),
];

/// One quadrature point on the reference element `ξ ∈ [0, 1]`: weight, shape functions
/// and their `ξ`-derivatives.
#[derive(Clone, Copy, Debug)]
pub struct QuadraturePoint {
    pub xi: f64,
    pub weight: f64,
    pub n: [f64; MAX_NODES],
    pub dn: [f64; MAX_NODES],
}

/// Lagrange shape functions on equally spaced nodes `ξ_a = a/p` and their derivatives.
pub fn shape(order: Order, xi: f64) -> ([f64; MAX_NODES], [f64; MAX_NODES]) {
    match order {
        Order::Linear => ([1.0 - xi, xi, 0.0], [-1.0, 1.0, 0.0]),
        Order::Quadratic => (
            [
                (1.0 - xi) * (1.0 - 2.0 * xi),
                4.0 * xi * (1.0 - xi),
                xi * (2.0 * xi - 1.0),
            ],
            [4.0 * xi - 3.0, 4.0 - 8.0 * xi, 4.0 * xi - 1.0],
        ),
    }
}

/// Gauss–Legendre rule on `[0, 1]` used for an element of the given order: 2 points for
/// linear and 3 for quadratic elements.
pub fn quadrature(order: Order) -> Vec<QuadraturePoint> {
    let rule: &[(f64, f64)] = match order {
        Order::Linear => &GAUSS_2,
        Order::Quadratic => &GAUSS_3,
    };
    rule.iter()
        .map(|&(x, w)| {
            let xi = 0.5 * (x + 1.0);
            let (n, dn) = shape(order, xi);
            QuadraturePoint {
                xi,
                weight: 0.5 * w,
                n,
                dn,
            }
        })
        .collect()
}

/// Interpolated quaternion `q(ξ)` and its arc-length derivative `q'(ξ)` on an element of
/// length `h` (m) with nodal quaternions `q` (the first `order.nodes()` used).
pub fn interpolate(
    order: Order,
    q: &[[f64; 4]; MAX_NODES],
    xi: f64,
    h: f64,
) -> ([f64; 4], [f64; 4]) {
    let (n, dn) = shape(order, xi);
    let mut qv = [0.0; 4];
    let mut dq = [0.0; 4];
    for a in 0..order.nodes() {
        for k in 0..4 {
            qv[k] += n[a] * q[a][k];
            dq[k] += dn[a] / h * q[a][k];
        }
    }
    (qv, dq)
}
