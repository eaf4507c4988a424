//! The extended wobble model: the Whipple bicycle with laterally slipping
//! tyres (first-order relaxation of slip and camber), a twist of the front
//! subframe about an axis at the steering head (spring-damper), and the
//! rider's upper torso hinged at the hip (spring-damper). 14 states:
//!
//! `x = (phi, phi_r, delta, beta, v, r, dphi, dphi_r, ddelta, dbeta,
//!       alpha1', gamma1', alpha2', gamma2')`
//!
//! (1 front, 2 rear tyre). Tyre forces and moments per unit wheel load:
//! `F_y = N (c_Fa alpha' + c_Fg gamma')`, `M_z = N (-c_Ma alpha' + c_Mg gamma')`,
//! `M_x = -N c_Mxg gamma`, with `(sigma / u) alpha'' + alpha' = alpha` and the
//! same for camber. The equations of motion come from [`crate::multibody`].

use nalgebra::DMatrix;

use crate::multibody::{self, Frame, Geometry, Linearised, RigidBody, N_COORDS, N_SPEEDS};
use crate::params::{ParamError, ParamSet, Problem, Unit};
use crate::whipple::{non_negative, positive, Benchmark, Body, Wheel};

/// A tyre's coefficients, per unit wheel load.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tyre {
    /// Cornering stiffness `c_Fa / N`, 1/rad.
    pub cornering_stiffness: f64,
    /// Camber stiffness `c_Fg / N`, 1/rad.
    pub camber_stiffness: f64,
    /// Self-aligning moment `c_Ma / N`, m/rad.
    pub aligning_coefficient: f64,
    /// Camber twisting moment `c_Mg / N`, m/rad.
    pub twisting_coefficient: f64,
    /// Overturning moment `c_Mxg / N`, m/rad.
    pub overturning_coefficient: f64,
    /// Relaxation length of slip `sigma`, m.
    pub relaxation_length: f64,
    /// Relaxation length of camber, m.
    pub camber_relaxation_length: f64,
}

/// The parameters of the extended model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WobbleParams {
    /// Wheelbase, trail, steer axis tilt, gravity as in the benchmark.
    pub wheelbase: f64,
    /// Trail, m.
    pub trail: f64,
    /// Steer axis tilt from vertical, rad.
    pub steer_axis_tilt: f64,
    /// Gravity, m/s^2.
    pub gravity: f64,
    /// Rear wheel.
    pub rear_wheel: Wheel,
    /// Front wheel.
    pub front_wheel: Wheel,
    /// Main frame with the rider's lower body and what the rack carries
    /// (a file's `[rider_legs]`, when it has one, lumped into its
    /// `[rear_frame]`: the legs held rigid with the frame).
    pub rear_frame: Body,
    /// Rider's upper torso (with head and arms), and the legs when a file
    /// seats them on the hinge (`[seated_legs]`).
    pub torso: Body,
    /// Height coordinate of the hip hinge, m.
    pub hip_z: f64,
    /// Hip (torso lean) stiffness, N m/rad.
    pub hip_stiffness: f64,
    /// Hip damping, N m s/rad.
    pub hip_damping: f64,
    /// Front frame above the twist axis.
    pub front_frame: Body,
    /// Fork below the twist axis, without the wheel.
    pub fork: Body,
    /// Height coordinate where the twist axis crosses the steer axis, m.
    pub twist_z: f64,
    /// The twist axis's angle from the normal to the steer axis, rad
    /// (`steer_head.axis_angle`, default 0: perpendicular to the steer axis).
    pub twist_axis_angle: f64,
    /// Steering-head twist stiffness, N m/rad.
    pub head_stiffness: f64,
    /// Steering-head twist damping, N m s/rad.
    pub head_damping: f64,
    /// Steering damping (bearings, rider's hands), N m s/rad.
    pub steer_damping: f64,
    /// Front tyre.
    pub front_tyre: Tyre,
    /// Rear tyre.
    pub rear_tyre: Tyre,
}

/// The excitations of [`WobbleModel::input_matrix`], in input order.
pub const INPUTS: [&str; 4] = [
    "steer_torque",
    "hip_torque",
    "front_path_slope",
    "rear_path_slope",
];

/// The state names, in state order.
pub const STATES: [&str; 14] = [
    "phi", "phi_r", "delta", "beta", "v", "r", "dphi", "dphi_r", "ddelta", "dbeta", "alpha1'",
    "gamma1'", "alpha2'", "gamma2'",
];

impl Tyre {
    fn from_set(set: &ParamSet, section: &str) -> Result<Self, ParamError> {
        let key = |k: &str| format!("{section}.{k}");
        let get = |k: &str, u| set.get(&key(k), u);
        let sigma = get("relaxation_length", Unit::Length)?;
        let t = Self {
            cornering_stiffness: get("cornering_stiffness", Unit::PerRadian)?,
            camber_stiffness: get("camber_stiffness", Unit::PerRadian)?,
            aligning_coefficient: get("aligning_coefficient", Unit::MetrePerRadian)?,
            twisting_coefficient: get("twisting_coefficient", Unit::MetrePerRadian)?,
            overturning_coefficient: get("overturning_coefficient", Unit::MetrePerRadian)?,
            relaxation_length: sigma,
            camber_relaxation_length: set.get_or(
                &key("camber_relaxation_length"),
                Unit::Length,
                sigma,
            )?,
        };
        positive(set, &key("cornering_stiffness"), t.cornering_stiffness)?;
        positive(set, &key("relaxation_length"), t.relaxation_length)?;
        positive(
            set,
            &key("camber_relaxation_length"),
            t.camber_relaxation_length,
        )?;
        Ok(t)
    }
}

impl WobbleParams {
    /// The parameters of a `wobble` parameter set, checked.
    pub fn from_set(set: &ParamSet) -> Result<Self, ParamError> {
        let base = Benchmark::from_set(set)?;
        let get = |k: &str, u| set.get(k, u);
        let p = Self {
            wheelbase: base.wheelbase,
            trail: base.trail,
            steer_axis_tilt: base.steer_axis_tilt,
            gravity: base.gravity,
            rear_wheel: base.rear_wheel,
            front_wheel: base.front_wheel,
            rear_frame: match set.quantity("rider_legs.mass") {
                Some(_) => base.rear_frame.lump(&Body::from_set(set, "rider_legs")?),
                None => base.rear_frame,
            },
            front_frame: base.front_frame,
            // `[seated_legs]`: the legs on the hinge with the upper body,
            // the whole rider rolling on the saddle.
            torso: match set.quantity("seated_legs.mass") {
                Some(_) => Body::from_set(set, "torso")?.lump(&Body::from_set(set, "seated_legs")?),
                None => Body::from_set(set, "torso")?,
            },
            hip_z: get("hip.z", Unit::Length)?,
            hip_stiffness: get("hip.stiffness", Unit::TorsionalStiffness)?,
            hip_damping: get("hip.damping", Unit::TorsionalDamping)?,
            fork: Body::from_set(set, "fork")?,
            twist_z: get("steer_head.z", Unit::Length)?,
            twist_axis_angle: set.get_or("steer_head.axis_angle", Unit::Angle, 0.0)?,
            head_stiffness: get("steer_head.stiffness", Unit::TorsionalStiffness)?,
            head_damping: get("steer_head.damping", Unit::TorsionalDamping)?,
            steer_damping: set.get_or("steer.damping", Unit::TorsionalDamping, 0.0)?,
            front_tyre: Tyre::from_set(set, "front_tyre")?,
            rear_tyre: Tyre::from_set(set, "rear_tyre")?,
        };
        non_negative(set, "hip.stiffness", p.hip_stiffness)?;
        non_negative(set, "hip.damping", p.hip_damping)?;
        positive(set, "steer_head.stiffness", p.head_stiffness)?;
        non_negative(set, "steer_head.damping", p.head_damping)?;
        non_negative(set, "steer.damping", p.steer_damping)?;
        let (front, rear) = p.wheel_loads_n();
        if front <= 0.0 || rear <= 0.0 {
            return Err(set.error(
                "rear_frame.x",
                Problem::Unphysical(format!(
                    "the mass centre is not between the contact points (wheel loads {front:.1} N front, {rear:.1} N rear)"
                )),
            ));
        }
        Ok(p)
    }

    /// The Whipple bicycle of the same masses: torso lumped into the rear
    /// frame, fork into the front frame.
    #[must_use]
    pub fn to_benchmark(&self) -> Benchmark {
        Benchmark {
            wheelbase: self.wheelbase,
            trail: self.trail,
            steer_axis_tilt: self.steer_axis_tilt,
            gravity: self.gravity,
            rear_wheel: self.rear_wheel,
            rear_frame: self.rear_frame.lump(&self.torso),
            front_frame: self.front_frame.lump(&self.fork),
            front_wheel: self.front_wheel,
        }
    }

    /// Static wheel loads (front, rear), N.
    #[must_use]
    pub fn wheel_loads_n(&self) -> (f64, f64) {
        let b = self.to_benchmark();
        let bodies = [
            (b.rear_wheel.mass, 0.0),
            (b.rear_frame.mass, b.rear_frame.x),
            (b.front_frame.mass, b.front_frame.x),
            (b.front_wheel.mass, b.wheelbase),
        ];
        let mass: f64 = bodies.iter().map(|(m, _)| m).sum();
        let moment: f64 = bodies.iter().map(|(m, x)| m * x).sum();
        let front = self.gravity * moment / self.wheelbase;
        (front, self.gravity * mass - front)
    }

    /// The multibody description.
    #[must_use]
    pub fn description(&self) -> (Geometry, Vec<RigidBody>) {
        let geo = Geometry {
            wheelbase: self.wheelbase,
            trail: self.trail,
            steer_axis_tilt: self.steer_axis_tilt,
            rear_radius: self.rear_wheel.radius,
            front_radius: self.front_wheel.radius,
            hip_z: self.hip_z,
            twist_z: self.twist_z,
            twist_axis_angle: self.twist_axis_angle,
            gravity: self.gravity,
        };
        let bodies = vec![
            multibody::wheel_body(Frame::Rear, 0.0, &self.rear_wheel),
            multibody::frame_body(Frame::Rear, &self.rear_frame),
            multibody::frame_body(Frame::Torso, &self.torso),
            multibody::frame_body(Frame::FrontUpper, &self.front_frame),
            multibody::frame_body(Frame::FrontSub, &self.fork),
            multibody::wheel_body(Frame::FrontSub, self.wheelbase, &self.front_wheel),
        ];
        (geo, bodies)
    }
}

/// The extended model, linearised once, evaluated at any speed.
#[derive(Clone, Debug, PartialEq)]
pub struct WobbleModel {
    /// Its parameters.
    pub params: WobbleParams,
    /// Its linearised equations.
    pub lin: Linearised,
    m_inv: DMatrix<f64>,
}

/// Offsets in the state vector.
const Q0: usize = 0;
const W0: usize = N_COORDS;
const T0: usize = N_COORDS + N_SPEEDS;

impl WobbleModel {
    /// The model of a `wobble` parameter set.
    pub fn from_set(set: &ParamSet) -> Result<Self, ParamError> {
        Ok(Self::new(WobbleParams::from_set(set)?))
    }

    /// The model of checked parameters.
    #[must_use]
    pub fn new(params: WobbleParams) -> Self {
        let (geo, bodies) = params.description();
        let lin = multibody::linearise(&geo, &bodies);
        // Positive definite for positive masses and inertias.
        let m_inv = lin
            .m
            .clone()
            .try_inverse()
            .unwrap_or_else(|| DMatrix::zeros(N_SPEEDS, N_SPEEDS));
        Self { params, lin, m_inv }
    }

    /// The state names.
    #[must_use]
    pub fn state_names(&self) -> Vec<&'static str> {
        STATES.to_vec()
    }

    /// The 14 x 14 state matrix at `speed_mps`.
    #[must_use]
    pub fn state_matrix(&self, speed_mps: f64) -> DMatrix<f64> {
        let u = speed_mps;
        let p = &self.params;
        let n = STATES.len();
        // Generalised forces Q = fq q + fw w + ft tyre.
        let mut fq = -&self.lin.k;
        let mut fw = -u * &self.lin.g;
        let mut ft = DMatrix::zeros(N_SPEEDS, 4);
        fq[(2 + multibody::PHI_R, multibody::PHI_R)] -= p.hip_stiffness;
        fw[(2 + multibody::PHI_R, 2 + multibody::PHI_R)] -= p.hip_damping;
        fq[(2 + multibody::BETA, multibody::BETA)] -= p.head_stiffness;
        fw[(2 + multibody::BETA, 2 + multibody::BETA)] -= p.head_damping;
        fw[(2 + multibody::DELTA, 2 + multibody::DELTA)] -= p.steer_damping;
        let (n_front, n_rear) = p.wheel_loads_n();
        let mut a = DMatrix::zeros(n, n);
        for (i, (tyre, load)) in [(&p.front_tyre, n_front), (&p.rear_tyre, n_rear)]
            .into_iter()
            .enumerate()
        {
            let c = &self.lin.tyres[i];
            let (col_a, col_g) = (2 * i, 2 * i + 1);
            for s in 0..N_SPEEDS {
                let f = c.force_w[(0, s)];
                let mz = c.yaw_w[(0, s)];
                ft[(s, col_a)] +=
                    load * (tyre.cornering_stiffness * f - tyre.aligning_coefficient * mz);
                ft[(s, col_g)] +=
                    load * (tyre.camber_stiffness * f + tyre.twisting_coefficient * mz);
                for k in 0..N_COORDS {
                    fq[(s, k)] -=
                        load * tyre.overturning_coefficient * c.roll_w[(0, s)] * c.camber_q[(0, k)];
                }
            }
            // Relaxation: sigma/u alpha'' = alpha - alpha', alpha = -v_sy / u.
            let (ra, rg) = (T0 + col_a, T0 + col_g);
            let (sa, sg) = (tyre.relaxation_length, tyre.camber_relaxation_length);
            for k in 0..N_COORDS {
                a[(ra, Q0 + k)] = -u * c.slip_q[(0, k)] / sa;
                a[(rg, Q0 + k)] = u * c.camber_q[(0, k)] / sg;
            }
            for s in 0..N_SPEEDS {
                a[(ra, W0 + s)] = -c.slip_w[(0, s)] / sa;
            }
            a[(ra, ra)] = -u / sa;
            a[(rg, rg)] = -u / sg;
        }
        for k in 0..N_COORDS {
            a[(Q0 + k, W0 + 2 + k)] = 1.0;
        }
        a.view_mut((W0, Q0), (N_SPEEDS, N_COORDS))
            .copy_from(&(&self.m_inv * fq));
        a.view_mut((W0, W0), (N_SPEEDS, N_SPEEDS))
            .copy_from(&(&self.m_inv * fw));
        a.view_mut((W0, T0), (N_SPEEDS, 4))
            .copy_from(&(&self.m_inv * ft));
        a
    }

    /// The 14 x 4 input matrix `B` at `speed_mps` of `x' = A x + B e`, for
    /// the excitations `e` named by [`INPUTS`]: the rider's steer torque
    /// (handlebar against the main frame) and hip torque (torso against the
    /// main frame), N m, and the slope of the road's lateral irregularity
    /// under the front and the rear tyre, rad (a path that turns by `dy/ds`
    /// adds that to the tyre's slip angle before relaxation).
    #[must_use]
    pub fn input_matrix(&self, speed_mps: f64) -> DMatrix<f64> {
        let mut forces = DMatrix::zeros(N_SPEEDS, 2);
        forces[(2 + multibody::DELTA, 0)] = 1.0;
        forces[(2 + multibody::PHI_R, 1)] = 1.0;
        let mut b = DMatrix::zeros(STATES.len(), INPUTS.len());
        b.view_mut((W0, 0), (N_SPEEDS, 2))
            .copy_from(&(&self.m_inv * forces));
        for (i, tyre) in [&self.params.front_tyre, &self.params.rear_tyre]
            .into_iter()
            .enumerate()
        {
            b[(T0 + 2 * i, 2 + i)] = speed_mps / tyre.relaxation_length;
        }
        b
    }
}
