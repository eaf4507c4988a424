//! The bicycle as a multibody description, linearised about upright
//! straight running at forward speed `u` by Kane's method (derivation in
//! `host-tools/docs/model.md`).
//!
//! Topology (fixed): four frames, each carried by a chain of revolute joints
//! from the ground-level *heading frame* that moves with the rear contact
//! point at lateral velocity `v` and yaw rate `r`:
//!
//! | frame | chain | bodies |
//! |---|---|---|
//! | rear | roll `phi` (x axis at the ground), pitch (rear axle, dependent) | main frame, rider's lower body, rear wheel |
//! | torso | rear + hip `phi_r` (x axis at hip height) | rider's upper torso |
//! | front upper | rear + steer `delta` (steer axis) | handlebar, fork crown |
//! | front sub | front upper + twist `beta` (axis through the steer axis at the steering head, in the plane of symmetry; perpendicular to the steer axis unless turned) | fork blades, front wheel |
//!
//! Generalised speeds `w = (v, r, dphi, dphi_r, ddelta, dbeta)`,
//! coordinates `q = (phi, phi_r, delta, beta)`. The linear equations are
//!
//! `M w' + u G w + K q = Q`
//!
//! with `M` from the partial velocities at the nominal configuration, `G`
//! from the heading frame's turning (`u r` acceleration of every point) and
//! the wheels' spin (gyroscopic moments), and `K` the Hessian of the
//! potential energy with the pitch solved from the front wheel touching the
//! ground (second order, exact closed form: see the notes). `Q` holds what
//! the caller adds: tyre forces, springs, dampers.

use nalgebra::{DMatrix, Matrix3, RowDVector, Vector3};

/// The frames of the topology.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Frame {
    /// Main frame with the rear wheel and the rider's lower body.
    Rear,
    /// Rider's upper torso.
    Torso,
    /// Front frame above the twist axis.
    FrontUpper,
    /// Front frame below the twist axis, with the front wheel.
    FrontSub,
}

/// Number of generalised speeds.
pub const N_SPEEDS: usize = 6;
/// Number of coordinates.
pub const N_COORDS: usize = 4;
/// Index of `v` in `w`.
pub const V: usize = 0;
/// Index of `r` in `w`.
pub const R: usize = 1;
/// Coordinate indices in `q`; their rates are `w[2 + k]`.
pub const PHI: usize = 0;
/// Torso roll.
pub const PHI_R: usize = 1;
/// Steer.
pub const DELTA: usize = 2;
/// Twist.
pub const BETA: usize = 3;

/// A rigid body of the description, at the nominal configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct RigidBody {
    /// The frame carrying it.
    pub frame: Frame,
    /// Mass, kg.
    pub mass: f64,
    /// Mass centre, m (x forward, y right, z down; origin at the rear contact).
    pub com: Vector3<f64>,
    /// Inertia tensor about the mass centre, kg m^2.
    pub inertia: Matrix3<f64>,
    /// For a wheel: its radius, m (spinning at `u / radius` about y).
    pub wheel_radius: Option<f64>,
}

/// Joint geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    /// Wheelbase, m.
    pub wheelbase: f64,
    /// Trail, m.
    pub trail: f64,
    /// Steer axis tilt from vertical, rad.
    pub steer_axis_tilt: f64,
    /// Rear wheel radius, m.
    pub rear_radius: f64,
    /// Front wheel radius, m.
    pub front_radius: f64,
    /// z of the hip hinge (an x-parallel axis), m.
    pub hip_z: f64,
    /// z where the twist axis crosses the steer axis, m.
    pub twist_z: f64,
    /// The twist axis's angle from the normal to the steer axis, in the
    /// plane of symmetry, rad: 0 is perpendicular to the steer axis
    /// (forward and up), `-steer_axis_tilt` horizontal (a roll of the front
    /// assembly about a longitudinal axis), positive turns it towards the
    /// vertical.
    pub twist_axis_angle: f64,
    /// Gravity, m/s^2.
    pub gravity: f64,
}

#[derive(Clone, Copy)]
struct Joint {
    axis: Vector3<f64>,
    point: Vector3<f64>,
    /// Coordinate index; `None` for the dependent pitch.
    coord: Option<usize>,
}

/// The linearised equations and the contact kinematics.
#[derive(Clone, Debug, PartialEq)]
pub struct Linearised {
    /// Mass matrix (6 x 6).
    pub m: DMatrix<f64>,
    /// Speed-proportional matrix, times `u` (6 x 6).
    pub g: DMatrix<f64>,
    /// Gravity stiffness (6 x 4).
    pub k: DMatrix<f64>,
    /// Rear (index 1) and front (index 0) tyre kinematics.
    pub tyres: [Contact; 2],
}

/// How one wheel's contact moves, to first order.
#[derive(Clone, Debug, PartialEq)]
pub struct Contact {
    /// Lateral slip velocity `v_sy = slip_w . w + u slip_q . q`.
    pub slip_w: RowDVector<f64>,
    /// See `slip_w` (1 x 4).
    pub slip_q: RowDVector<f64>,
    /// Camber angle `gamma = camber_q . q` (1 x 4).
    pub camber_q: RowDVector<f64>,
    /// Lateral partial velocity of the contact point (1 x 6): a lateral
    /// force F adds `F force_w^T` to Q.
    pub force_w: RowDVector<f64>,
    /// Partial angular velocity of the wheel about z (1 x 6).
    pub yaw_w: RowDVector<f64>,
    /// Partial angular velocity of the wheel about x (1 x 6).
    pub roll_w: RowDVector<f64>,
}

struct Chains {
    joints: [Joint; 5],
}

const ROLL: usize = 0;
const PITCH: usize = 1;
const HIP: usize = 2;
const STEER: usize = 3;
const TWIST: usize = 4;

impl Chains {
    fn new(geo: &Geometry) -> Self {
        let (sl, cl) = geo.steer_axis_tilt.sin_cos();
        let steer_axis = Vector3::new(sl, 0.0, cl);
        let steer_ground = Vector3::new(geo.wheelbase + geo.trail, 0.0, 0.0);
        let twist_point = steer_ground + steer_axis * (geo.twist_z / cl);
        Self {
            joints: [
                Joint {
                    axis: Vector3::x(),
                    point: Vector3::zeros(),
                    coord: Some(PHI),
                },
                Joint {
                    axis: Vector3::y(),
                    point: Vector3::new(0.0, 0.0, -geo.rear_radius),
                    coord: None,
                },
                Joint {
                    axis: Vector3::x(),
                    point: Vector3::new(0.0, 0.0, geo.hip_z),
                    coord: Some(PHI_R),
                },
                Joint {
                    axis: steer_axis,
                    point: steer_ground,
                    coord: Some(DELTA),
                },
                Joint {
                    axis: {
                        let (s, c) = (geo.steer_axis_tilt + geo.twist_axis_angle).sin_cos();
                        Vector3::new(c, 0.0, -s)
                    },
                    point: twist_point,
                    coord: Some(BETA),
                },
            ],
        }
    }

    /// Joints carrying `frame`, root first.
    fn chain(frame: Frame) -> &'static [usize] {
        match frame {
            Frame::Rear => &[ROLL, PITCH],
            Frame::Torso => &[ROLL, PITCH, HIP],
            Frame::FrontUpper => &[ROLL, PITCH, STEER],
            Frame::FrontSub => &[ROLL, PITCH, STEER, TWIST],
        }
    }

    /// Partial velocities (3 x 6) and partial angular velocities (3 x 6)
    /// of the point `p` fixed in `frame`.
    fn partials(&self, frame: Frame, p: &Vector3<f64>) -> (DMatrix<f64>, DMatrix<f64>) {
        let mut jv = DMatrix::zeros(3, N_SPEEDS);
        let mut jw = DMatrix::zeros(3, N_SPEEDS);
        jv.set_column(V, &Vector3::y());
        jv.set_column(R, &Vector3::z().cross(p));
        jw.set_column(R, &Vector3::z());
        for &j in Self::chain(frame) {
            let joint = &self.joints[j];
            if let Some(k) = joint.coord {
                jv.set_column(2 + k, &joint.axis.cross(&(p - joint.point)));
                jw.set_column(2 + k, &joint.axis);
            }
        }
        (jv, jw)
    }

    /// d p / d q_j for the point `p` of `frame` (zero if `j` does not carry it).
    fn d1(&self, frame: Frame, j: usize, p: &Vector3<f64>, free: bool) -> Vector3<f64> {
        if !Self::chain(frame).contains(&j) {
            return Vector3::zeros();
        }
        let joint = &self.joints[j];
        let arm = if free { *p } else { p - joint.point };
        joint.axis.cross(&arm)
    }

    /// d^2 p / d q_i d q_j: with `i` at or before `j` in the chain,
    /// `n_i x (n_j x (p - o_j))` (the rotation about `i` also turns joint
    /// `j`). `free` marks a direction rather than a point.
    fn d2(&self, frame: Frame, i: usize, j: usize, p: &Vector3<f64>, free: bool) -> Vector3<f64> {
        let chain = Self::chain(frame);
        let (Some(pi), Some(pj)) = (
            chain.iter().position(|&c| c == i),
            chain.iter().position(|&c| c == j),
        ) else {
            return Vector3::zeros();
        };
        let (first, second) = if pi <= pj { (i, j) } else { (j, i) };
        let inner = self.d1(frame, second, p, free);
        self.joints[first].axis.cross(&inner)
    }
}

/// Index of a coordinate's joint.
fn joint_of(coord: usize) -> usize {
    [ROLL, HIP, STEER, TWIST][coord]
}

/// The linearised equations of `bodies` on `geo`.
#[must_use]
pub fn linearise(geo: &Geometry, bodies: &[RigidBody]) -> Linearised {
    let chains = Chains::new(geo);
    let mut m = DMatrix::zeros(N_SPEEDS, N_SPEEDS);
    let mut g = DMatrix::zeros(N_SPEEDS, N_SPEEDS);
    for b in bodies {
        let (jv, jw) = chains.partials(b.frame, &b.com);
        m += b.mass * jv.transpose() * &jv + jw.transpose() * b.inertia * &jw;
        // Every point of the turning heading frame accelerates by u r e_y.
        let lateral = jv.transpose() * Vector3::y() * b.mass;
        for i in 0..N_SPEEDS {
            g[(i, R)] += lateral[i];
        }
        if let Some(radius) = b.wheel_radius {
            // Spin -u/radius about the axle y: d(spin momentum)/dt is
            // I_yy (-u/radius) (omega x e_y).
            let spin = b.inertia[(1, 1)] / radius;
            g += spin * jw.transpose() * Vector3::y().cross_matrix() * &jw;
        }
    }
    let k = gravity_stiffness(&chains, geo, bodies);
    let rear = contact(&chains, Frame::Rear, Vector3::zeros());
    let front = contact(
        &chains,
        Frame::FrontSub,
        Vector3::new(geo.wheelbase, 0.0, 0.0),
    );
    Linearised {
        m,
        g,
        k,
        tyres: [front, rear],
    }
}

/// The Hessian of the potential energy `-g sum m z` in `q`, the pitch
/// eliminated through the front contact constraint
/// `h = z_c + r_F sqrt(1 - a_z^2) = 0` (wheel centre `c`, axle `a`). Pitch
/// is second order, so `d^2 V = V_qq - (V_theta / h_theta) h_qq`.
fn gravity_stiffness(chains: &Chains, geo: &Geometry, bodies: &[RigidBody]) -> DMatrix<f64> {
    let gz = |v: Vector3<f64>| v.z;
    let centre = Vector3::new(geo.wheelbase, 0.0, -geo.front_radius);
    let v_theta: f64 = bodies
        .iter()
        .map(|b| -geo.gravity * b.mass * gz(chains.d1(b.frame, PITCH, &b.com, false)))
        .sum();
    let h_theta = gz(chains.d1(Frame::FrontSub, PITCH, &centre, false));
    let mut k = DMatrix::zeros(N_SPEEDS, N_COORDS);
    for i in 0..N_COORDS {
        for j in 0..N_COORDS {
            let (ji, jj) = (joint_of(i), joint_of(j));
            let v_ij: f64 = bodies
                .iter()
                .map(|b| -geo.gravity * b.mass * gz(chains.d2(b.frame, ji, jj, &b.com, false)))
                .sum();
            let a_zi = gz(chains.d1(Frame::FrontSub, ji, &Vector3::y(), true));
            let a_zj = gz(chains.d1(Frame::FrontSub, jj, &Vector3::y(), true));
            let h_ij = gz(chains.d2(Frame::FrontSub, ji, jj, &centre, false))
                - geo.front_radius * a_zi * a_zj;
            k[(2 + i, j)] = v_ij - v_theta / h_theta * h_ij;
        }
    }
    k
}

/// Kinematics of the contact at `point` of the wheel in `frame`.
fn contact(chains: &Chains, frame: Frame, point: Vector3<f64>) -> Contact {
    // The material point of the wheel at the contact, without the spin
    // (whose velocity there is along the wheel's heading).
    let (jv, jw) = chains.partials(frame, &point);
    let force_w = jv.row(1).into_owned();
    let mut slip_q = RowDVector::zeros(N_COORDS);
    let mut camber_q = RowDVector::zeros(N_COORDS);
    for k in 0..N_COORDS {
        let da = chains.d1(frame, joint_of(k), &Vector3::y(), true);
        // Heading error: the lateral unit vector is (a_x, 1, 0) to first
        // order, so u e_x contributes u a_x.
        slip_q[(0, k)] = da.x;
        camber_q[(0, k)] = da.z;
    }
    Contact {
        slip_w: force_w.clone(),
        slip_q,
        camber_q,
        force_w,
        yaw_w: jw.row(2).into_owned(),
        roll_w: jw.row(0).into_owned(),
    }
}

/// The Whipple limit of a linearised description: both contacts without
/// lateral slip, torso and twist locked. Returns `(M, C1, K0 g, K2)` in
/// `(phi, delta)`, comparable with the benchmark's closed forms.
#[must_use]
pub fn constrained_whipple(lin: &Linearised) -> [DMatrix<f64>; 4] {
    constrained(lin, &[PHI, DELTA])
}

/// The description with both contacts rolling without lateral slip and
/// only the coordinates `keep` free (the others locked): `(M, C1, K0 g, K2)`
/// of `M q'' + u C1 q' + (g K0 + u^2 K2) q = 0` in the kept coordinates.
/// The lateral velocity and yaw rate follow from the two rolling
/// constraints, `w = T q' + u E q`, and Kane's equations are projected on
/// `T`.
#[must_use]
pub fn constrained(lin: &Linearised, keep: &[usize]) -> [DMatrix<f64>; 4] {
    let n = keep.len();
    let mut a2 = DMatrix::zeros(2, 2);
    let mut bw = DMatrix::zeros(2, n);
    let mut bq = DMatrix::zeros(2, n);
    for (row, c) in lin.tyres.iter().enumerate() {
        a2[(row, 0)] = c.slip_w[(0, V)];
        a2[(row, 1)] = c.slip_w[(0, R)];
        for (col, &k) in keep.iter().enumerate() {
            bw[(row, col)] = c.slip_w[(0, 2 + k)];
            bq[(row, col)] = c.slip_q[(0, k)];
        }
    }
    let inv = a2.try_inverse().unwrap_or_else(|| DMatrix::zeros(2, 2));
    let dep_w = -&inv * bw;
    let dep_q = -&inv * bq;
    let mut t = DMatrix::zeros(N_SPEEDS, n);
    let mut e = DMatrix::zeros(N_SPEEDS, n);
    for (col, &k) in keep.iter().enumerate() {
        t[(V, col)] = dep_w[(0, col)];
        t[(R, col)] = dep_w[(1, col)];
        e[(V, col)] = dep_q[(0, col)];
        e[(R, col)] = dep_q[(1, col)];
        t[(2 + k, col)] = 1.0;
    }
    let k_sub = lin.k.select_columns(keep);
    let tt = t.transpose();
    [
        &tt * &lin.m * &t,
        &tt * (&lin.m * &e + &lin.g * &t),
        &tt * k_sub,
        &tt * &lin.g * &e,
    ]
}
/// The tensor of a body in the plane of symmetry.
#[must_use]
pub fn planar_inertia(xx: f64, xz: f64, yy: f64, zz: f64) -> Matrix3<f64> {
    Matrix3::new(xx, 0.0, xz, 0.0, yy, 0.0, xz, 0.0, zz)
}

/// A wheel of radius `radius` centred `x` ahead of the rear contact.
#[must_use]
pub fn wheel_body(frame: Frame, x: f64, wheel: &crate::whipple::Wheel) -> RigidBody {
    RigidBody {
        frame,
        mass: wheel.mass,
        com: Vector3::new(x, 0.0, -wheel.radius),
        inertia: planar_inertia(wheel.inertia_xx, 0.0, wheel.inertia_yy, wheel.inertia_xx),
        wheel_radius: Some(wheel.radius),
    }
}

/// A body of the benchmark's kind carried by `frame`.
#[must_use]
pub fn frame_body(frame: Frame, b: &crate::whipple::Body) -> RigidBody {
    RigidBody {
        frame,
        mass: b.mass,
        com: Vector3::new(b.x, 0.0, b.z),
        inertia: planar_inertia(b.inertia_xx, b.inertia_xz, b.inertia_yy, b.inertia_zz),
        wheel_radius: None,
    }
}
