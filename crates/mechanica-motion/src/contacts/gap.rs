//! The gaps g_i(q) and their rates ġ_i = n·(ẋ − ẋ_other) of a run's contacts (M.21).

use super::UnilateralContact;
use crate::error::StepFailure;
use mechanica_dynamics::DynamicsError;
use mechanica_kinematics::tree::KinematicTree;

/// A contact's gap (m) and its rate (m/s) at one state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Gap {
    pub value: f64,
    pub rate: f64,
}

/// The gap and rate of every contact at (q, q̇), in the tree's current charts.
pub(crate) fn gaps(
    tree: &KinematicTree,
    contacts: &[UnilateralContact],
    q: &[f64],
    q_dot: &[f64],
) -> Result<Vec<Gap>, StepFailure> {
    let kinematics = |e| StepFailure::Dynamics(DynamicsError::Kinematics(e));
    let mut ws = tree.workspace();
    tree.update_positions(&mut ws, q).map_err(kinematics)?;
    tree.update_velocities(&mut ws, q_dot).map_err(kinematics)?;
    let mut out = Vec::with_capacity(contacts.len());
    for c in contacts {
        let n = c.contact.normal_w;
        let p = &c.contact.point;
        let mut x = ws.point_position(p.body, &p.p_bq).map_err(kinematics)?;
        let mut v = ws.point_velocity(p.body, &p.p_bq).map_err(kinematics)?;
        if let Some(o) = &c.contact.other {
            x -= ws.point_position(o.body, &o.p_bq).map_err(kinematics)?;
            v -= ws.point_velocity(o.body, &o.p_bq).map_err(kinematics)?;
        }
        let gap = Gap {
            value: n.dot(&x) - c.offset,
            rate: n.dot(&v),
        };
        if !(gap.value.is_finite() && gap.rate.is_finite()) {
            return Err(StepFailure::NonFinite { what: "contact gap" });
        }
        out.push(gap);
    }
    Ok(out)
}
