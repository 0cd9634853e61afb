//! The preallocated workspace of a kinematic tree and the recursions that fill it.

use super::{BaseState, Joint, KinematicTree};
use crate::KinematicsError;
use crate::rotation::{
    check_finite_vec, check_result, check_rotation_vector, exp_unchecked, right_jacobian, right_jacobian_rate,
};
use nalgebra::{Matrix3, Rotation3, Vector3};

/// Which recursions are up to date.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Stage {
    None,
    Positions,
    Velocities,
    Accelerations,
}

/// Every buffer the tree computations need, sized once for a tree (no allocation per call).
/// All vectors are world components; "origin" is the body frame's origin o_B (on the joint).
#[derive(Debug, Clone, PartialEq)]
pub struct Workspace {
    base: BaseState,
    stage: Stage,
    q: Vec<f64>,
    q_dot: Vec<f64>,
    rotation: Vec<Matrix3<f64>>,
    position: Vec<Vector3<f64>>,
    /// o_B − o_P (o_P the base origin for a root), formed from the placement and the joint's
    /// own translation rather than as a difference of positions, so that lever arms stay exact
    /// to rounding for bodies far from the world origin.
    offset: Vec<Vector3<f64>>,
    omega: Vec<Vector3<f64>>,
    velocity: Vec<Vector3<f64>>,
    omega_dot: Vec<Vector3<f64>>,
    acceleration: Vec<Vector3<f64>>,
    col_w: Vec<Vector3<f64>>,
    col_v: Vec<Vector3<f64>>,
    col_w_dot: Vec<Vector3<f64>>,
    col_v_dot: Vec<Vector3<f64>>,
}

impl Workspace {
    pub(super) fn new(bodies: usize, nv: usize) -> Self {
        let z = Vector3::zeros();
        Workspace {
            base: BaseState::default(),
            stage: Stage::None,
            q: vec![0.0; nv],
            q_dot: vec![0.0; nv],
            rotation: vec![Matrix3::identity(); bodies],
            position: vec![z; bodies],
            offset: vec![z; bodies],
            omega: vec![z; bodies],
            velocity: vec![z; bodies],
            omega_dot: vec![z; bodies],
            acceleration: vec![z; bodies],
            col_w: vec![z; nv],
            col_v: vec![z; nv],
            col_w_dot: vec![z; nv],
            col_v_dot: vec![z; nv],
        }
    }

    /// Prescribes the base state (pose, velocity, acceleration at the current time). Rejects
    /// non-finite vectors. Invalidates all computed quantities.
    pub fn set_base(&mut self, base: BaseState) -> Result<(), KinematicsError> {
        check_finite_vec(&base.position, "base position")?;
        check_finite_vec(&base.omega, "base angular velocity")?;
        check_finite_vec(&base.velocity, "base velocity")?;
        check_finite_vec(&base.omega_dot, "base angular acceleration")?;
        check_finite_vec(&base.acceleration, "base acceleration")?;
        if let Some(value) = base.rotation.matrix().iter().copied().find(|v| !v.is_finite()) {
            return Err(KinematicsError::NonFinite {
                what: "base rotation entry",
                value,
            });
        }
        self.base = base;
        self.stage = Stage::None;
        Ok(())
    }

    /// The base state in use.
    pub fn base(&self) -> &BaseState {
        &self.base
    }

    /// Number of bodies this workspace was sized for.
    pub fn body_count(&self) -> usize {
        self.rotation.len()
    }

    fn check(&self, stage: Stage, body: usize) -> Result<(), KinematicsError> {
        if self.stage < stage {
            return Err(KinematicsError::WorkspaceNotReady {
                what: match stage {
                    Stage::Positions | Stage::None => "positions not computed (call update_positions)",
                    Stage::Velocities => "velocities not computed (call update_velocities)",
                    Stage::Accelerations => "accelerations not computed (call update_accelerations)",
                },
            });
        }
        if body >= self.rotation.len() {
            return Err(KinematicsError::BodyOutOfRange {
                body,
                bodies: self.rotation.len(),
            });
        }
        Ok(())
    }

    /// R_WB of `body`.
    pub fn rotation(&self, body: usize) -> Result<Rotation3<f64>, KinematicsError> {
        self.check(Stage::Positions, body)?;
        Ok(Rotation3::from_matrix_unchecked(self.rotation[body]))
    }

    /// p_WB: the world position of `body`'s origin.
    pub fn position(&self, body: usize) -> Result<Vector3<f64>, KinematicsError> {
        self.check(Stage::Positions, body)?;
        Ok(self.position[body])
    }

    /// o_B − o_P: `body`'s origin relative to its parent's (the base origin for a root), formed
    /// from the placement and the joint's translation, so exact to rounding however far the
    /// mechanism is from the world origin (a difference of world positions is not).
    pub fn parent_offset(&self, body: usize) -> Result<Vector3<f64>, KinematicsError> {
        self.check(Stage::Positions, body)?;
        Ok(self.offset[body])
    }

    /// World position x = R_WB p_BQ + p_WB of the body point with body coordinates `p_bq` (1.5).
    pub fn point_position(&self, body: usize, p_bq: &Vector3<f64>) -> Result<Vector3<f64>, KinematicsError> {
        self.check(Stage::Positions, body)?;
        finite_result(self.rotation[body] * p_bq + self.position[body], "point position")
    }

    /// Angular velocity ω of `body` (world).
    pub fn angular_velocity(&self, body: usize) -> Result<Vector3<f64>, KinematicsError> {
        self.check(Stage::Velocities, body)?;
        Ok(self.omega[body])
    }

    /// Velocity of `body`'s origin (world).
    pub fn origin_velocity(&self, body: usize) -> Result<Vector3<f64>, KinematicsError> {
        self.check(Stage::Velocities, body)?;
        Ok(self.velocity[body])
    }

    /// Velocity of a body point (body coordinates `p_bq`), by (2.13).
    pub fn point_velocity(&self, body: usize, p_bq: &Vector3<f64>) -> Result<Vector3<f64>, KinematicsError> {
        self.check(Stage::Velocities, body)?;
        finite_result(
            self.velocity[body] + self.omega[body].cross(&(self.rotation[body] * p_bq)),
            "point velocity",
        )
    }

    /// Angular acceleration ω̇ of `body` (world).
    pub fn angular_acceleration(&self, body: usize) -> Result<Vector3<f64>, KinematicsError> {
        self.check(Stage::Accelerations, body)?;
        Ok(self.omega_dot[body])
    }

    /// Acceleration of `body`'s origin (world).
    pub fn origin_acceleration(&self, body: usize) -> Result<Vector3<f64>, KinematicsError> {
        self.check(Stage::Accelerations, body)?;
        Ok(self.acceleration[body])
    }

    /// Acceleration of a body point, by (2.18).
    pub fn point_acceleration(&self, body: usize, p_bq: &Vector3<f64>) -> Result<Vector3<f64>, KinematicsError> {
        self.check(Stage::Accelerations, body)?;
        let r = self.rotation[body] * p_bq;
        let w = self.omega[body];
        finite_result(
            self.acceleration[body] + self.omega_dot[body].cross(&r) + w.cross(&w.cross(&r)),
            "point acceleration",
        )
    }

    /// ∂x/∂t at fixed q for a body point: the drag velocity of the prescribed base motion,
    /// ω_0 × (x − p_W0) + v_0 (zero for a fixed base).
    pub fn drag_velocity(&self, body: usize, p_bq: &Vector3<f64>) -> Result<Vector3<f64>, KinematicsError> {
        self.check(Stage::Positions, body)?;
        let x = self.rotation[body] * p_bq + self.position[body];
        finite_result(
            self.base.velocity + self.base.omega.cross(&(x - self.base.position)),
            "drag velocity",
        )
    }

    /// The motion column (w_k, v_k) of coordinate k: angular velocity of its body i and velocity
    /// of o_i per unit q̇_k (world). See the module docs of [`super`].
    pub fn motion_column(&self, k: usize) -> Result<(Vector3<f64>, Vector3<f64>), KinematicsError> {
        self.check_dof(Stage::Positions, k)?;
        Ok((self.col_w[k], self.col_v[k]))
    }

    /// The time derivatives (ẇ_k, v̇_k) of the motion column k along the current (q, q̇).
    pub fn motion_column_rate(&self, k: usize) -> Result<(Vector3<f64>, Vector3<f64>), KinematicsError> {
        self.check_dof(Stage::Velocities, k)?;
        Ok((self.col_w_dot[k], self.col_v_dot[k]))
    }

    /// The column k shifted to the world point x: (w_k, w_k × (x − o_i) + v_k), i.e. ∂x/∂q_k
    /// for a point x moving with coordinate k's body (1.37).
    pub fn column_at(
        &self,
        tree: &KinematicTree,
        k: usize,
        x: &Vector3<f64>,
    ) -> Result<(Vector3<f64>, Vector3<f64>), KinematicsError> {
        self.check_dof(Stage::Positions, k)?;
        let i = tree.dof_body[k];
        let shifted = finite_result(
            self.col_w[k].cross(&(x - self.position[i])) + self.col_v[k],
            "shifted column",
        )?;
        Ok((self.col_w[k], shifted))
    }

    fn check_dof(&self, stage: Stage, k: usize) -> Result<(), KinematicsError> {
        self.check(stage, 0)?;
        if k >= self.col_w.len() {
            return Err(KinematicsError::WrongLength {
                what: "coordinate index (must be < dof)",
                expected: self.col_w.len(),
                got: k,
            });
        }
        Ok(())
    }

    /// Fails with [`KinematicsError::NonFiniteResult`] naming `quantity` unless every vector
    /// of `stage_values` is finite.
    fn check_stage(values: &[Vector3<f64>], quantity: &'static str) -> Result<(), KinematicsError> {
        check_result(values.iter().flat_map(|v| v.iter()), quantity)
    }

    /// The coordinates of the last [`KinematicTree::update_positions`].
    pub fn q(&self) -> &[f64] {
        &self.q
    }

    /// Ok when the velocities of the current positions are computed
    /// ([`KinematicTree::update_velocities`] since the last position update), so that
    /// [`Workspace::q_dot`] belongs to the state; [`KinematicsError::WorkspaceNotReady`] otherwise.
    pub fn check_velocities(&self) -> Result<(), KinematicsError> {
        if self.stage < Stage::Velocities {
            return Err(KinematicsError::WorkspaceNotReady {
                what: "velocities not computed (call update_velocities)",
            });
        }
        Ok(())
    }

    /// The velocities of the last [`KinematicTree::update_velocities`].
    pub fn q_dot(&self) -> &[f64] {
        &self.q_dot
    }
}

/// `v` when it is finite, [`KinematicsError::NonFiniteResult`] naming `quantity` otherwise.
fn finite_result(v: Vector3<f64>, quantity: &'static str) -> Result<Vector3<f64>, KinematicsError> {
    check_result(v.iter(), quantity)?;
    Ok(v)
}

impl KinematicTree {
    fn check_workspace(&self, ws: &Workspace) -> Result<(), KinematicsError> {
        if ws.rotation.len() != self.body_count() || ws.col_w.len() != self.nv {
            return Err(KinematicsError::WorkspaceNotReady {
                what: "workspace was made for a different tree",
            });
        }
        Ok(())
    }

    /// Forward kinematics: every body pose and every motion column at coordinates `q`.
    pub fn update_positions(&self, ws: &mut Workspace, q: &[f64]) -> Result<(), KinematicsError> {
        self.check_workspace(ws)?;
        self.check_vector(q, "q")?;
        self.check_rotation_vectors(q)?;
        ws.stage = Stage::None;
        ws.q.copy_from_slice(q);
        let base_r = *ws.base.rotation.matrix();
        let base_p = ws.base.position;
        for &b in &self.order {
            let (r_wp, p_wp) = match self.parent[b] {
                Some(p) => (ws.rotation[p], ws.position[p]),
                None => (base_r, base_p),
            };
            let d_wj = r_wp * self.p_pj[b];
            let p_wj = p_wp + d_wj;
            if let Joint::Revolute { .. } = self.joint[b] {
                let s = self.dof_start[b];
                let (sn, cs) = q[s].sin_cos();
                let (k, k2, a_p) = &self.rev_terms[b];
                let r_pb = self.r_pj[b] + k * sn + k2 * (1.0 - cs);
                ws.rotation[b] = r_wp * r_pb;
                ws.position[b] = p_wj;
                ws.offset[b] = d_wj;
                ws.col_w[s] = r_wp * a_p;
                ws.col_v[s] = Vector3::zeros();
                continue;
            }
            let r_wj = r_wp * self.r_pj[b];
            let s = self.dof_start[b];
            // The joint's translation t: o_B = o_J + t.
            let (r_wb, t) = match self.joint[b] {
                Joint::Revolute { .. } => continue, // handled above without forming R_WJ
                Joint::Prismatic { axis } => {
                    let a = r_wj * axis;
                    ws.col_w[s] = Vector3::zeros();
                    ws.col_v[s] = a;
                    (r_wj, a * q[s])
                }
                Joint::Spherical => {
                    let phi = Vector3::new(q[s], q[s + 1], q[s + 2]);
                    let r = r_wj * self.r_ref[b] * exp_unchecked(&phi).matrix();
                    let jw = r * right_jacobian(&phi);
                    for c in 0..3 {
                        ws.col_w[s + c] = jw.column(c).into_owned();
                        ws.col_v[s + c] = Vector3::zeros();
                    }
                    (r, Vector3::zeros())
                }
                Joint::Free => {
                    let phi = Vector3::new(q[s + 3], q[s + 4], q[s + 5]);
                    let r = r_wj * self.r_ref[b] * exp_unchecked(&phi).matrix();
                    let jw = r * right_jacobian(&phi);
                    for c in 0..3 {
                        ws.col_w[s + c] = Vector3::zeros();
                        ws.col_v[s + c] = r_wj.column(c).into_owned();
                        ws.col_w[s + 3 + c] = jw.column(c).into_owned();
                        ws.col_v[s + 3 + c] = Vector3::zeros();
                    }
                    (r, r_wj * Vector3::new(q[s], q[s + 1], q[s + 2]))
                }
                Joint::Planar => {
                    let (sn, cs) = q[s + 2].sin_cos();
                    let rz = Matrix3::new(cs, -sn, 0.0, sn, cs, 0.0, 0.0, 0.0, 1.0);
                    ws.col_w[s] = Vector3::zeros();
                    ws.col_v[s] = r_wj.column(0).into_owned();
                    ws.col_w[s + 1] = Vector3::zeros();
                    ws.col_v[s + 1] = r_wj.column(1).into_owned();
                    ws.col_w[s + 2] = r_wj.column(2).into_owned();
                    ws.col_v[s + 2] = Vector3::zeros();
                    (r_wj * rz, r_wj * Vector3::new(q[s], q[s + 1], 0.0))
                }
                Joint::Fixed => (r_wj, Vector3::zeros()),
            };
            ws.rotation[b] = r_wb;
            ws.position[b] = p_wj + t;
            ws.offset[b] = d_wj + t;
        }
        Workspace::check_stage(&ws.position, "body position")?;
        Workspace::check_stage(&ws.col_v, "motion column")?;
        ws.stage = Stage::Positions;
        Ok(())
    }

    /// Fails with [`KinematicsError::RotationAngleUnresolved`] when a spherical or free joint's
    /// rotation vector in `q` is longer than [`crate::rotation::ROTATION_VECTOR_LIMIT`].
    fn check_rotation_vectors(&self, q: &[f64]) -> Result<(), KinematicsError> {
        for body in 0..self.body_count() {
            if self.joint[body].has_rotation_vector() {
                let s = self.dof_start[body] + self.joint[body].rotation_offset();
                check_rotation_vector(&Vector3::new(q[s], q[s + 1], q[s + 2]), "joint rotation vector")?;
            }
        }
        Ok(())
    }

    /// Body velocities and motion-column rates at velocities `q_dot`, after
    /// [`KinematicTree::update_positions`]:
    /// ω_B = ω_P + Σ w_k q̇_k, v_B = v_P + ω_P × (o_B − o_P) + Σ v_k q̇_k.
    pub fn update_velocities(&self, ws: &mut Workspace, q_dot: &[f64]) -> Result<(), KinematicsError> {
        self.check_workspace(ws)?;
        ws.check(Stage::Positions, 0)?;
        self.check_vector(q_dot, "q_dot")?;
        ws.stage = Stage::Positions;
        ws.q_dot.copy_from_slice(q_dot);
        for &b in &self.order {
            let (w_p, v_p) = match self.parent[b] {
                Some(p) => (ws.omega[p], ws.velocity[p]),
                None => (ws.base.omega, ws.base.velocity),
            };
            let range = self.dof_range(b);
            let mut w = w_p;
            let mut v = v_p + w_p.cross(&ws.offset[b]);
            for k in range.clone() {
                w += ws.col_w[k] * q_dot[k];
                v += ws.col_v[k] * q_dot[k];
            }
            ws.omega[b] = w;
            ws.velocity[b] = v;
            let s = range.start;
            match self.joint[b] {
                Joint::Revolute { .. } => {
                    ws.col_w_dot[s] = w_p.cross(&ws.col_w[s]);
                    ws.col_v_dot[s] = Vector3::zeros();
                }
                Joint::Prismatic { .. } => {
                    ws.col_w_dot[s] = Vector3::zeros();
                    ws.col_v_dot[s] = w_p.cross(&ws.col_v[s]);
                }
                Joint::Spherical | Joint::Free => {
                    let r0 = self.joint[b].rotation_offset();
                    if r0 == 3 {
                        for c in 0..3 {
                            ws.col_w_dot[s + c] = Vector3::zeros();
                            ws.col_v_dot[s + c] = w_p.cross(&ws.col_v[s + c]);
                        }
                    }
                    let rs = s + r0;
                    let phi = Vector3::new(ws.q[rs], ws.q[rs + 1], ws.q[rs + 2]);
                    let phi_dot = Vector3::new(q_dot[rs], q_dot[rs + 1], q_dot[rs + 2]);
                    let jd = ws.rotation[b] * right_jacobian_rate(&phi, &phi_dot);
                    for c in 0..3 {
                        ws.col_w_dot[rs + c] = w.cross(&ws.col_w[rs + c]) + jd.column(c);
                        ws.col_v_dot[rs + c] = Vector3::zeros();
                    }
                }
                Joint::Planar => {
                    for c in 0..3 {
                        ws.col_w_dot[s + c] = w_p.cross(&ws.col_w[s + c]);
                        ws.col_v_dot[s + c] = w_p.cross(&ws.col_v[s + c]);
                    }
                }
                Joint::Fixed => {}
            }
        }
        Workspace::check_stage(&ws.omega, "body angular velocity")?;
        Workspace::check_stage(&ws.velocity, "body velocity")?;
        Workspace::check_stage(&ws.col_w_dot, "motion column rate")?;
        Workspace::check_stage(&ws.col_v_dot, "motion column rate")?;
        ws.stage = Stage::Velocities;
        Ok(())
    }

    /// Body accelerations at `q_ddot`, after [`KinematicTree::update_velocities`]:
    /// ω̇_B = ω̇_P + Σ (ẇ_k q̇_k + w_k q̈_k),
    /// a_B = a_P + ω̇_P × r + ω_P × (v_B − v_P) + Σ (v̇_k q̇_k + v_k q̈_k), r = o_B − o_P.
    pub fn update_accelerations(&self, ws: &mut Workspace, q_ddot: &[f64]) -> Result<(), KinematicsError> {
        self.check_workspace(ws)?;
        ws.check(Stage::Velocities, 0)?;
        self.check_vector(q_ddot, "q_ddot")?;
        ws.stage = Stage::Velocities;
        for &b in &self.order {
            let (wd_p, a_p, w_p, v_p) = match self.parent[b] {
                Some(p) => (ws.omega_dot[p], ws.acceleration[p], ws.omega[p], ws.velocity[p]),
                None => (ws.base.omega_dot, ws.base.acceleration, ws.base.omega, ws.base.velocity),
            };
            let mut wd = wd_p;
            let mut a = a_p + wd_p.cross(&ws.offset[b]) + w_p.cross(&(ws.velocity[b] - v_p));
            for k in self.dof_range(b) {
                wd += ws.col_w_dot[k] * ws.q_dot[k] + ws.col_w[k] * q_ddot[k];
                a += ws.col_v_dot[k] * ws.q_dot[k] + ws.col_v[k] * q_ddot[k];
            }
            ws.omega_dot[b] = wd;
            ws.acceleration[b] = a;
        }
        Workspace::check_stage(&ws.omega_dot, "body angular acceleration")?;
        Workspace::check_stage(&ws.acceleration, "body acceleration")?;
        ws.stage = Stage::Accelerations;
        Ok(())
    }

    fn check_jacobian_out(&self, out: &[f64], rows: usize) -> Result<(), KinematicsError> {
        if out.len() != rows * self.nv {
            return Err(KinematicsError::WrongLength {
                what: "Jacobian buffer",
                expected: rows * self.nv,
                got: out.len(),
            });
        }
        Ok(())
    }

    /// The point Jacobian ∂x/∂q (1.37) of the body point with body coordinates `p_bq`, into
    /// `out` as a 3×dof column-major array (column k = ∂x/∂q_k, world components; zero for
    /// coordinates that do not move the body). Needs [`KinematicTree::update_positions`].
    pub fn point_jacobian(
        &self,
        ws: &Workspace,
        body: usize,
        p_bq: &Vector3<f64>,
        out: &mut [f64],
    ) -> Result<(), KinematicsError> {
        self.check_workspace(ws)?;
        ws.check(Stage::Positions, body)?;
        self.check_jacobian_out(out, 3)?;
        check_finite_vec(p_bq, "body point")?;
        let lever = ws.rotation[body] * p_bq;
        self.fill_path_columns::<3>(ws, body, &lever, out, |k, r| {
            (ws.col_w[k].cross(r) + ws.col_v[k]).into()
        });
        check_result(out.iter(), "point Jacobian")
    }

    /// Zeroes `out` (W×dof, column-major) and writes column k = `column(k, x − o_i)` for every
    /// coordinate k on the path from `body` to the root, i being the body that k moves and x
    /// the point at `lever` = x − o_body from the body's origin. The levers are summed from the
    /// bodies' offsets, never formed as differences of world positions.
    fn fill_path_columns<const W: usize>(
        &self,
        ws: &Workspace,
        body: usize,
        lever: &Vector3<f64>,
        out: &mut [f64],
        column: impl Fn(usize, &Vector3<f64>) -> [f64; W],
    ) {
        out.fill(0.0);
        let mut lever = *lever;
        let mut b = Some(body);
        while let Some(i) = b {
            for k in self.dof_range(i) {
                out[W * k..W * k + W].copy_from_slice(&column(k, &lever));
            }
            lever += ws.offset[i];
            b = self.parent[i];
        }
    }

    /// The angular-velocity Jacobian ∂ω_B/∂q̇ of `body` into `out` (3×dof, column-major).
    pub fn angular_jacobian(&self, ws: &Workspace, body: usize, out: &mut [f64]) -> Result<(), KinematicsError> {
        self.check_workspace(ws)?;
        ws.check(Stage::Positions, body)?;
        self.check_jacobian_out(out, 3)?;
        self.fill_path_columns::<3>(ws, body, &Vector3::zeros(), out, |k, _| ws.col_w[k].into());
        check_result(out.iter(), "angular Jacobian")
    }

    /// The 6×dof body Jacobian of `body` (column-major; rows 0–2 angular velocity, rows 3–5
    /// velocity of the point with body coordinates `p_bq`, world components).
    pub fn body_jacobian(
        &self,
        ws: &Workspace,
        body: usize,
        p_bq: &Vector3<f64>,
        out: &mut [f64],
    ) -> Result<(), KinematicsError> {
        self.check_workspace(ws)?;
        ws.check(Stage::Positions, body)?;
        self.check_jacobian_out(out, 6)?;
        check_finite_vec(p_bq, "body point")?;
        let lever = ws.rotation[body] * p_bq;
        self.fill_path_columns::<6>(ws, body, &lever, out, |k, r| {
            let w = ws.col_w[k];
            let v = w.cross(r) + ws.col_v[k];
            [w.x, w.y, w.z, v.x, v.y, v.z]
        });
        check_result(out.iter(), "body Jacobian")
    }

    /// The time derivative J̇ of [`KinematicTree::point_jacobian`] along the current (q, q̇)
    /// (3×dof, column-major): column k = ẇ_k × (x − o_i) + w_k × (ẋ − ȯ_i) + v̇_k, which equals
    /// ∂ẋ/∂q_k (1.41). Needs [`KinematicTree::update_velocities`].
    pub fn point_jacobian_rate(
        &self,
        ws: &Workspace,
        body: usize,
        p_bq: &Vector3<f64>,
        out: &mut [f64],
    ) -> Result<(), KinematicsError> {
        self.check_workspace(ws)?;
        ws.check(Stage::Velocities, body)?;
        self.check_jacobian_out(out, 3)?;
        check_finite_vec(p_bq, "body point")?;
        let rb = ws.rotation[body] * p_bq;
        let x_dot = ws.velocity[body] + ws.omega[body].cross(&rb);
        let tree_body = &self.dof_body;
        self.fill_path_columns::<3>(ws, body, &rb, out, |k, r| {
            let r_dot = x_dot - ws.velocity[tree_body[k]];
            (ws.col_w_dot[k].cross(r) + ws.col_w[k].cross(&r_dot) + ws.col_v_dot[k]).into()
        });
        check_result(out.iter(), "point Jacobian rate")
    }

    /// The time derivative J̇_ω of [`KinematicTree::angular_jacobian`] (3×dof, column-major;
    /// column k = ẇ_k), so that ω̇_B = J_ω q̈ + J̇_ω q̇ (+ base terms). Needs velocities.
    pub fn angular_jacobian_rate(&self, ws: &Workspace, body: usize, out: &mut [f64]) -> Result<(), KinematicsError> {
        self.check_workspace(ws)?;
        ws.check(Stage::Velocities, body)?;
        self.check_jacobian_out(out, 3)?;
        self.fill_path_columns::<3>(ws, body, &Vector3::zeros(), out, |k, _| ws.col_w_dot[k].into());
        check_result(out.iter(), "angular Jacobian rate")
    }

    /// The velocity-product acceleration J̇ q̇ of a body point (plus the base's drag
    /// acceleration): the point's acceleration at q̈ = 0. Needs velocities.
    pub fn point_bias_acceleration(
        &self,
        ws: &Workspace,
        body: usize,
        p_bq: &Vector3<f64>,
    ) -> Result<Vector3<f64>, KinematicsError> {
        self.check_workspace(ws)?;
        ws.check(Stage::Velocities, body)?;
        check_finite_vec(p_bq, "body point")?;
        // Recompute along the chain root → body with q̈ = 0, without touching the workspace.
        let mut chain = Vec::with_capacity(self.depth[body] + 1);
        let mut b = Some(body);
        while let Some(i) = b {
            chain.push(i);
            b = self.parent[i];
        }
        let mut wd = ws.base.omega_dot;
        let mut a = ws.base.acceleration;
        let mut prev = None;
        for &i in chain.iter().rev() {
            let (w_p, v_p) = match prev {
                Some(p) => (ws.omega[p], ws.velocity[p]),
                None => (ws.base.omega, ws.base.velocity),
            };
            a += wd.cross(&ws.offset[i]) + w_p.cross(&(ws.velocity[i] - v_p));
            for k in self.dof_range(i) {
                wd += ws.col_w_dot[k] * ws.q_dot[k];
                a += ws.col_v_dot[k] * ws.q_dot[k];
            }
            prev = Some(i);
        }
        let r = ws.rotation[body] * p_bq;
        let w = ws.omega[body];
        finite_result(a + wd.cross(&r) + w.cross(&w.cross(&r)), "bias acceleration")
    }
}
