//! The extended model's non-holonomic counterpart, the seed paper's thick
//! line of Figure 4: the same bodies, both contacts rolling without lateral
//! slip (no tyre model), the rider's torso and the steering-head twist free
//! on their spring-dampers. 8 states:
//!
//! `x = (phi, phi_r, delta, beta, dphi, dphi_r, ddelta, dbeta)`.
//!
//! The lateral velocity and yaw rate follow from the two rolling
//! constraints ([`crate::multibody::constrained`]), giving
//! `M q'' + (u C1 + C) q' + (g K0 + u^2 K2 + K) q = 0` with the hip, twist
//! and steer springs and dampers in `K` and `C`.

use nalgebra::DMatrix;

use crate::multibody::{self, BETA, DELTA, PHI, PHI_R};
use crate::wobble::WobbleModel;

/// The state names, in state order.
pub const STATES: [&str; 8] = [
    "phi", "phi_r", "delta", "beta", "dphi", "dphi_r", "ddelta", "dbeta",
];

/// The constrained equations, ready to evaluate at any speed.
#[derive(Clone, Debug, PartialEq)]
pub struct NoSlipModel {
    m_inv: DMatrix<f64>,
    c1: DMatrix<f64>,
    c: DMatrix<f64>,
    k0g: DMatrix<f64>,
    k2: DMatrix<f64>,
    k: DMatrix<f64>,
}

impl NoSlipModel {
    /// The counterpart of `model`: its bodies and springs, no tyres.
    #[must_use]
    pub fn of(model: &WobbleModel) -> Self {
        let keep = [PHI, PHI_R, DELTA, BETA];
        let [m, c1, k0g, k2] = multibody::constrained(&model.lin, &keep);
        let p = &model.params;
        let mut k = DMatrix::zeros(4, 4);
        let mut c = DMatrix::zeros(4, 4);
        k[(1, 1)] = p.hip_stiffness;
        c[(1, 1)] = p.hip_damping;
        k[(3, 3)] = p.head_stiffness;
        c[(3, 3)] = p.head_damping;
        c[(2, 2)] = p.steer_damping;
        // Positive definite for positive masses (a projection of M).
        let m_inv = m.try_inverse().unwrap_or_else(|| DMatrix::zeros(4, 4));
        Self {
            m_inv,
            c1,
            c,
            k0g,
            k2,
            k,
        }
    }

    /// The 8 x 8 state matrix at `speed_mps`.
    #[must_use]
    pub fn state_matrix(&self, speed_mps: f64) -> DMatrix<f64> {
        let u = speed_mps;
        let stiffness = &self.k0g + &self.k2 * (u * u) + &self.k;
        let damping = &self.c1 * u + &self.c;
        let mut a = DMatrix::zeros(8, 8);
        a.view_mut((0, 4), (4, 4)).fill_with_identity();
        a.view_mut((4, 0), (4, 4))
            .copy_from(&(-&self.m_inv * stiffness));
        a.view_mut((4, 4), (4, 4))
            .copy_from(&(-&self.m_inv * damping));
        a
    }
}
