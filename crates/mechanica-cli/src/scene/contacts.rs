//! The scene's `[[contact]]` tables: unilateral contacts kept by `simulate` (theory
//! (M.21)–(M.23)). Each closing of a gap is located and resolved as an impact with the contact's
//! restitution law, and the report lists every impact with its energy loss beside the
//! integrator's drift over the free motion before it.
//!
//! ```toml
//! [[contact]]
//! name = "heel"                        # optional; shown in the report
//! body = "lower"                       # the body whose point strikes
//! point = [0.0, 0.0, -1.0]             # body coordinates, m
//! normal = [0.0, 0.0, 1.0]             # world, into the body (need not be of unit length)
//! offset = 0.0                         # the plane n·x = offset (n normalised), m
//! # other = "upper", other_point = [...]   a point of another body instead of the plane:
//! #                                        the gap is n·(x − x_other) − offset
//! restitution = 0.5                    # e ∈ [0, 1]
//! friction = 0.3                       # Coulomb coefficient ≥ 0
//! law = "stronge"                      # "stronge" (default), "poisson" or "newton"
//! ```

use super::{BodyIndex, Spanned, Validator};
use serde::Deserialize;

/// One unilateral contact as written in the scene.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// A name for the report (default "contact[i]").
    pub name: Option<String>,
    /// The striking body.
    pub body: Spanned<String>,
    /// Its contact point, body coordinates, m.
    #[serde(default)]
    pub point: [f64; 3],
    /// The normal, world, pointing into `body` (normalised when read).
    pub normal: Spanned<[f64; 3]>,
    /// The plane's offset along the unit normal, m (or the clearance from `other`'s point).
    #[serde(default)]
    pub offset: f64,
    /// Another body whose point is struck instead of the environment's plane.
    pub other: Option<Spanned<String>>,
    /// That body's point, its body coordinates, m.
    #[serde(default)]
    pub other_point: [f64; 3],
    /// Restitution coefficient in [0, 1] (default 0).
    pub restitution: Option<Spanned<f64>>,
    /// Coulomb friction coefficient ≥ 0 (default 0).
    pub friction: Option<Spanned<f64>>,
    /// "stronge" (default), "poisson" or "newton".
    pub law: Option<Spanned<String>>,
}

impl ContactSpec {
    /// The contact's name in the report.
    pub fn label(&self, index: usize) -> String {
        self.name.clone().unwrap_or_else(|| format!("contact[{index}]"))
    }

    /// The restitution coefficient (default 0).
    pub fn restitution(&self) -> f64 {
        self.restitution.as_ref().map_or(0.0, |e| *e.get_ref())
    }

    /// The friction coefficient (default 0).
    pub fn friction(&self) -> f64 {
        self.friction.as_ref().map_or(0.0, |f| *f.get_ref())
    }

    /// The restitution law's name.
    pub fn law_name(&self) -> &str {
        self.law.as_ref().map_or("stronge", |l| l.get_ref().as_str())
    }
}

/// The restitution laws a contact may name.
pub const CONTACT_LAWS: [&str; 3] = ["stronge", "poisson", "newton"];

impl<'a> Validator<'a> {
    /// Ok when every contact names existing bodies and a known law, with finite points, a
    /// finite non-zero normal, a finite offset, e ∈ [0, 1] and friction ≥ 0; and when the scene
    /// has no holonomic constraints or rotating frame besides (impacts are resolved for a free
    /// tree on a fixed base).
    pub(super) fn check_contacts(&self, index_of: &BodyIndex<'a>) -> Result<(), super::SceneError> {
        let Some(first) = self.scene.contacts.first() else {
            return Ok(());
        };
        if !self.scene.constraints.is_empty() || self.scene.rotating_frame.is_some() {
            let message = "contacts need a mechanism without [[constraint]] tables or a rotating frame".to_string();
            return Err(self.error(Some(first.body.span()), "contact[0]".into(), message));
        }
        for (i, spec) in self.scene.contacts.iter().enumerate() {
            let at = |field: &str| format!("contact[{i}].{field}");
            self.check_body(&spec.body, at("body"), index_of)?;
            if let Some(other) = &spec.other {
                self.check_body(other, at("other"), index_of)?;
            }
            self.check_contact_numbers(spec, &at)?;
        }
        Ok(())
    }

    fn check_contact_numbers(&self, spec: &ContactSpec, at: &dyn Fn(&str) -> String) -> Result<(), super::SceneError> {
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        let bad_point = [("point", &spec.point), ("other_point", &spec.other_point)]
            .into_iter()
            .find(|(_, p)| !finite(p.as_slice()));
        if let Some((field, p)) = bad_point {
            return Err(self.error(None, at(field), format!("{p:?} is not finite")));
        }
        let n = spec.normal.get_ref();
        if !finite(n) || n.iter().all(|x| *x == 0.0) {
            let message = format!("{n:?} must be finite and non-zero");
            return Err(self.error(Some(spec.normal.span()), at("normal"), message));
        }
        if !spec.offset.is_finite() {
            return Err(self.error(None, at("offset"), format!("{} is not finite", spec.offset)));
        }
        let span = |v: &Option<Spanned<f64>>| v.as_ref().map(|v| v.span());
        let e = spec.restitution();
        if !(0.0..=1.0).contains(&e) {
            let message = format!("{e} is not in [0, 1]");
            return Err(self.error(span(&spec.restitution), at("restitution"), message));
        }
        let f = spec.friction();
        if f.is_nan() || f < 0.0 {
            let message = format!("{f} must be ≥ 0");
            return Err(self.error(span(&spec.friction), at("friction"), message));
        }
        if let Some(law) = &spec.law
            && !CONTACT_LAWS.contains(&law.get_ref().as_str())
        {
            let message = format!("\"{}\" is not one of {CONTACT_LAWS:?}", law.get_ref());
            return Err(self.error(Some(law.span()), at("law"), message));
        }
        Ok(())
    }
}
