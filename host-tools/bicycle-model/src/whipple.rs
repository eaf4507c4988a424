//! The Whipple bicycle as in Meijaard, Papadopoulos, Ruina and Schwab (2007),
//! "Linearized dynamics equations for the balance and steer of a bicycle: a
//! benchmark and review", Proc. R. Soc. A 463: the benchmark parameters
//! (their Table 1 symbols), the closed forms of their Appendix A for the
//! matrices of
//!
//! `M q'' + u C1 q' + (g K0 + u^2 K2) q = f`,   `q = (phi, delta)`,
//!
//! and the state matrix `A(u)` for `x = (phi, delta, dphi, ddelta)`.
//!
//! Axes as in the paper: x forward, y to the right, z down, origin at the
//! rear contact point; `phi` is roll to the right, `delta` steer to the right.

use nalgebra::{DMatrix, Matrix2};

use crate::params::{ParamError, ParamSet, Problem, Unit};

/// A wheel: a rotationally symmetric disc.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wheel {
    /// Radius, m.
    pub radius: f64,
    /// Mass, kg.
    pub mass: f64,
    /// Moment of inertia about a diameter, kg m^2.
    pub inertia_xx: f64,
    /// Moment of inertia about the axle, kg m^2.
    pub inertia_yy: f64,
}

/// A body in the plane of symmetry: mass centre at (x, 0, z), inertia about
/// it with the only product of inertia in the x-z plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Body {
    /// Mass centre ahead of the rear contact, m.
    pub x: f64,
    /// Mass centre height coordinate (negative above the ground), m.
    pub z: f64,
    /// Mass, kg.
    pub mass: f64,
    /// Inertia about the mass centre, kg m^2.
    pub inertia_xx: f64,
    /// Product of inertia, kg m^2.
    pub inertia_xz: f64,
    /// Inertia about the mass centre, kg m^2.
    pub inertia_yy: f64,
    /// Inertia about the mass centre, kg m^2.
    pub inertia_zz: f64,
}

/// The benchmark parameters (Meijaard et al. 2007, Table 1 symbols).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Benchmark {
    /// Wheelbase `w`, m.
    pub wheelbase: f64,
    /// Trail `c`, m.
    pub trail: f64,
    /// Steer axis tilt from vertical `lambda`, rad.
    pub steer_axis_tilt: f64,
    /// Gravity `g`, m/s^2.
    pub gravity: f64,
    /// Rear wheel R.
    pub rear_wheel: Wheel,
    /// Rear frame B (with the rider).
    pub rear_frame: Body,
    /// Front frame H (fork and handlebar).
    pub front_frame: Body,
    /// Front wheel F.
    pub front_wheel: Wheel,
}

/// The matrices of the linearised equations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WhippleMatrices {
    /// Mass matrix M.
    pub m: Matrix2<f64>,
    /// Velocity-proportional matrix C1 (multiplied by u).
    pub c1: Matrix2<f64>,
    /// Gravity stiffness K0 (multiplied by g).
    pub k0: Matrix2<f64>,
    /// Velocity stiffness K2 (multiplied by u^2).
    pub k2: Matrix2<f64>,
    /// Gravity, m/s^2.
    pub gravity: f64,
}

/// The state names of the Whipple model, in state order.
pub const STATES: [&str; 4] = ["phi", "delta", "dphi", "ddelta"];

impl Wheel {
    fn from_set(set: &ParamSet, section: &str) -> Result<Self, ParamError> {
        let get = |k: &str, u| set.get(&format!("{section}.{k}"), u);
        let wheel = Self {
            radius: get("radius", Unit::Length)?,
            mass: get("mass", Unit::Mass)?,
            inertia_xx: get("inertia_xx", Unit::Inertia)?,
            inertia_yy: get("inertia_yy", Unit::Inertia)?,
        };
        positive(set, &format!("{section}.radius"), wheel.radius)?;
        non_negative(set, &format!("{section}.mass"), wheel.mass)?;
        positive(set, &format!("{section}.inertia_xx"), wheel.inertia_xx)?;
        positive(set, &format!("{section}.inertia_yy"), wheel.inertia_yy)?;
        Ok(wheel)
    }
}

impl Body {
    /// Reads `section.{x,z,mass,inertia_*}` and checks it is a body.
    pub fn from_set(set: &ParamSet, section: &str) -> Result<Self, ParamError> {
        let get = |k: &str, u| set.get(&format!("{section}.{k}"), u);
        let body = Self {
            x: get("x", Unit::Length)?,
            z: get("z", Unit::Length)?,
            mass: get("mass", Unit::Mass)?,
            inertia_xx: get("inertia_xx", Unit::Inertia)?,
            inertia_xz: get("inertia_xz", Unit::Inertia)?,
            inertia_yy: get("inertia_yy", Unit::Inertia)?,
            inertia_zz: get("inertia_zz", Unit::Inertia)?,
        };
        positive(set, &format!("{section}.mass"), body.mass)?;
        body.check_inertia(set, section)?;
        Ok(body)
    }

    /// A rigid body's inertia tensor is positive semi-definite (the
    /// principal minors of the x-z block, and yy, non-negative up to
    /// round-off): a slender rod, with no inertia about its own axis, is a
    /// body too.
    fn check_inertia(&self, set: &ParamSet, section: &str) -> Result<(), ParamError> {
        let (xx, zz, xz) = (self.inertia_xx, self.inertia_zz, self.inertia_xz);
        let det = xx * zz - xz * xz;
        let round_off = 1e-12 * (xx * xx + zz * zz + xz * xz).sqrt().max(f64::MIN_POSITIVE);
        if xx >= 0.0 && self.inertia_yy >= 0.0 && zz >= 0.0 && det >= -round_off * (xx + zz) {
            return Ok(());
        }
        Err(set.error(
            &format!("{section}.inertia_xx"),
            Problem::Unphysical(format!(
                "the inertia tensor of {section} is not positive semi-definite \
                 (xx {}, yy {}, zz {}, xz {} kg m^2)",
                self.inertia_xx, self.inertia_yy, self.inertia_zz, self.inertia_xz
            )),
        ))
    }

    /// This body and `other` as one: masses summed, the mass centre
    /// between them, the inertias moved to it by parallel axes (in the
    /// plane of symmetry, with the benchmark's sign of the product).
    pub(crate) fn lump(&self, other: &Self) -> Self {
        let (a, b) = (self, other);
        let mass = a.mass + b.mass;
        let x = (a.mass * a.x + b.mass * b.x) / mass;
        let z = (a.mass * a.z + b.mass * b.z) / mass;
        let sum = |f: &dyn Fn(&Self) -> f64| f(a) + f(b);
        let (dxa, dza, dxb, dzb) = (a.x - x, a.z - z, b.x - x, b.z - z);
        Self {
            x,
            z,
            mass,
            inertia_xx: sum(&|p| p.inertia_xx) + a.mass * dza * dza + b.mass * dzb * dzb,
            inertia_xz: sum(&|p| p.inertia_xz) - a.mass * dxa * dza - b.mass * dxb * dzb,
            inertia_yy: sum(&|p| p.inertia_yy)
                + a.mass * (dxa * dxa + dza * dza)
                + b.mass * (dxb * dxb + dzb * dzb),
            inertia_zz: sum(&|p| p.inertia_zz) + a.mass * dxa * dxa + b.mass * dxb * dxb,
        }
    }
}

pub(crate) fn positive(set: &ParamSet, key: &str, v: f64) -> Result<(), ParamError> {
    if v > 0.0 {
        Ok(())
    } else {
        Err(set.error(key, Problem::Unphysical(format!("{v} must be positive"))))
    }
}

pub(crate) fn non_negative(set: &ParamSet, key: &str, v: f64) -> Result<(), ParamError> {
    if v >= 0.0 {
        Ok(())
    } else {
        Err(set.error(
            key,
            Problem::Unphysical(format!("{v} must not be negative")),
        ))
    }
}

impl Benchmark {
    /// The benchmark parameters of a parameter set, checked.
    pub fn from_set(set: &ParamSet) -> Result<Self, ParamError> {
        let b = Self {
            wheelbase: set.get("geometry.wheelbase", Unit::Length)?,
            trail: set.get("geometry.trail", Unit::Length)?,
            steer_axis_tilt: set.get("geometry.steer_axis_tilt", Unit::Angle)?,
            gravity: set.get("geometry.gravity", Unit::Acceleration)?,
            rear_wheel: Wheel::from_set(set, "rear_wheel")?,
            rear_frame: Body::from_set(set, "rear_frame")?,
            front_frame: Body::from_set(set, "front_frame")?,
            front_wheel: Wheel::from_set(set, "front_wheel")?,
        };
        positive(set, "geometry.wheelbase", b.wheelbase)?;
        positive(set, "geometry.gravity", b.gravity)?;
        if b.steer_axis_tilt.abs() >= std::f64::consts::FRAC_PI_2 {
            return Err(set.error(
                "geometry.steer_axis_tilt",
                Problem::Unphysical("the steer axis must be tilted less than 90 deg".into()),
            ));
        }
        Ok(b)
    }

    /// M, C1, K0 and K2 from the closed forms of Appendix A.
    #[must_use]
    #[allow(clippy::similar_names)]
    pub fn matrices(&self) -> WhippleMatrices {
        let (w, c, lam) = (self.wheelbase, self.trail, self.steer_axis_tilt);
        let (rw, fw) = (&self.rear_wheel, &self.front_wheel);
        let (b, h) = (&self.rear_frame, &self.front_frame);
        let (sl, cl) = lam.sin_cos();
        // Whole bicycle (A1-A6), the wheels' zz inertia equal to their xx.
        let m_t = rw.mass + b.mass + h.mass + fw.mass;
        let x_t = (b.x * b.mass + h.x * h.mass + w * fw.mass) / m_t;
        let z_t = (-rw.radius * rw.mass + b.z * b.mass + h.z * h.mass - fw.radius * fw.mass) / m_t;
        let i_txx = rw.inertia_xx
            + b.inertia_xx
            + h.inertia_xx
            + fw.inertia_xx
            + rw.mass * rw.radius.powi(2)
            + b.mass * b.z.powi(2)
            + h.mass * h.z.powi(2)
            + fw.mass * fw.radius.powi(2);
        let i_txz = b.inertia_xz + h.inertia_xz - b.mass * b.x * b.z - h.mass * h.x * h.z
            + fw.mass * w * fw.radius;
        let i_tzz = rw.inertia_xx
            + b.inertia_zz
            + h.inertia_zz
            + fw.inertia_xx
            + b.mass * b.x.powi(2)
            + h.mass * h.x.powi(2)
            + fw.mass * w.powi(2);
        // Front assembly A = H + F (A7-A12).
        let m_a = h.mass + fw.mass;
        let x_a = (h.x * h.mass + w * fw.mass) / m_a;
        let z_a = (h.z * h.mass - fw.radius * fw.mass) / m_a;
        let i_axx = h.inertia_xx
            + fw.inertia_xx
            + h.mass * (h.z - z_a).powi(2)
            + fw.mass * (fw.radius + z_a).powi(2);
        let i_axz = h.inertia_xz - h.mass * (h.x - x_a) * (h.z - z_a)
            + fw.mass * (w - x_a) * (fw.radius + z_a);
        let i_azz = h.inertia_zz
            + fw.inertia_xx
            + h.mass * (h.x - x_a).powi(2)
            + fw.mass * (w - x_a).powi(2);
        // About the steer axis (A13-A16).
        let u_a = (x_a - w - c) * cl - z_a * sl;
        let i_all =
            m_a * u_a.powi(2) + i_axx * sl.powi(2) + 2.0 * i_axz * sl * cl + i_azz * cl.powi(2);
        let i_alx = -m_a * u_a * z_a + i_axx * sl + i_axz * cl;
        let i_alz = m_a * u_a * x_a + i_axz * sl + i_azz * cl;
        let mu = c / w * cl;
        // Gyrostatic coefficients (A17-A20).
        let s_r = rw.inertia_yy / rw.radius;
        let s_f = fw.inertia_yy / fw.radius;
        let s_t = s_r + s_f;
        let s_a = m_a * u_a + mu * m_t * x_t;
        let m_pd = i_alx + mu * i_txz;
        WhippleMatrices {
            m: Matrix2::new(
                i_txx,
                m_pd,
                m_pd,
                i_all + 2.0 * mu * i_alz + mu.powi(2) * i_tzz,
            ),
            k0: Matrix2::new(m_t * z_t, -s_a, -s_a, -s_a * sl),
            k2: Matrix2::new(
                0.0,
                (s_t - m_t * z_t) / w * cl,
                0.0,
                (s_a + s_f * sl) / w * cl,
            ),
            c1: Matrix2::new(
                0.0,
                mu * s_t + s_f * cl + i_txz / w * cl - mu * m_t * z_t,
                -(mu * s_t + s_f * cl),
                i_alz / w * cl + mu * (s_a + i_tzz / w * cl),
            ),
            gravity: self.gravity,
        }
    }
}

impl WhippleMatrices {
    /// The state matrix `A(u)` of `x' = A x`, `x = (phi, delta, dphi, ddelta)`.
    #[must_use]
    pub fn state_matrix(&self, speed_mps: f64) -> DMatrix<f64> {
        let u = speed_mps;
        // M is positive definite for any physical bicycle (checked on input).
        let m_inv = self.m.try_inverse().unwrap_or_else(Matrix2::zeros);
        let stiff = -m_inv * (self.gravity * self.k0 + u * u * self.k2);
        let damp = -m_inv * (u * self.c1);
        let mut a = DMatrix::zeros(4, 4);
        a[(0, 2)] = 1.0;
        a[(1, 3)] = 1.0;
        for i in 0..2 {
            for j in 0..2 {
                a[(2 + i, j)] = stiff[(i, j)];
                a[(2 + i, 2 + j)] = damp[(i, j)];
            }
        }
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Parallel axes by hand: 2 kg at 1 m ahead of and 1 m above a 2 kg
    /// point body put the mass centre half way, and each mass 0.5 m off it
    /// in x and z adds 2 x 2 x 0.25 = 1 kg m^2 to Ixx and Izz, 2 to Iyy and
    /// -2 x 2 x (0.5 x -0.5) = +1 to Ixz.
    #[test]
    fn two_point_masses_lump_by_parallel_axes() {
        let point = Body {
            mass: 2.0,
            x: 0.0,
            z: 0.0,
            inertia_xx: 0.0,
            inertia_xz: 0.0,
            inertia_yy: 0.0,
            inertia_zz: 0.0,
        };
        let body = Body {
            mass: 2.0,
            x: 1.0,
            z: -1.0,
            inertia_xx: 0.1,
            inertia_xz: 0.0,
            inertia_yy: 0.2,
            inertia_zz: 0.3,
        };
        for l in [point.lump(&body), body.lump(&point)] {
            assert_eq!((l.mass, l.x, l.z), (4.0, 0.5, -0.5));
            let got = [l.inertia_xx, l.inertia_xz, l.inertia_yy, l.inertia_zz];
            for (got, want) in got.iter().zip([1.1, 1.0, 2.2, 1.3]) {
                assert!((got - want).abs() < 1e-12, "{l:?}");
            }
        }
    }
}
