//! The scene's `[[constraint]]` tables: holonomic constraints f(q) = 0 closing loops or holding
//! points (FM 4.61), solved by Lagrange multipliers in the dynamics step.
//!
//! ```toml
//! [[constraint]]
//! name = "closure"                     # optional; shown in the report
//! kind = "points"                      # "points", "plane", "distance" or "coordinate"
//! a = "coupler"                        # points / distance: two ends, body name or "ground"
//! a_point = [1.0, 0.0, 0.0]            # body coordinates (world for the ground), m
//! b = "rocker"
//! b_point = [0.0, 0.0, 1.0]
//! directions = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]   # points: optional (default x, y, z)
//! # plane:      a, a_point, normal = [0, 0, 1], offset = 0.0 (the point stays on n·x = offset)
//! # distance:   a, a_point, b, b_point, length = 1.0 (a massless rod)
//! # coordinate: joint = "crank", coordinate = 0, value = 0.3 (default: the joint's q0)
//! ```

use super::{BodyIndex, Spanned, Validator, unlocated_zero};
use serde::Deserialize;

/// The kinds of constraint a scene may name.
pub const CONSTRAINT_KINDS: [&str; 4] = ["points", "plane", "distance", "coordinate"];

/// One holonomic constraint as written in the scene.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstraintSpec {
    /// A name for the report (default "constraint[i]").
    pub name: Option<String>,
    /// One of [`CONSTRAINT_KINDS`].
    pub kind: Spanned<String>,
    /// First point's body, or "ground" (points, plane, distance).
    pub a: Option<Spanned<String>>,
    /// First point, body coordinates (world for the ground), m.
    #[serde(default)]
    pub a_point: [f64; 3],
    /// Second point's body, or "ground" (points, distance).
    pub b: Option<Spanned<String>>,
    /// Second point, m.
    #[serde(default)]
    pub b_point: [f64; 3],
    /// World directions along which the points coincide (points; default the three axes).
    pub directions: Option<Spanned<Vec<[f64; 3]>>>,
    /// The plane's normal, world (plane; need not be of unit length).
    pub normal: Option<Spanned<[f64; 3]>>,
    /// The plane's offset along the unit normal, m (plane).
    #[serde(default)]
    pub offset: f64,
    /// The rod's length L > 0, m (distance).
    pub length: Option<Spanned<f64>>,
    /// The joint whose coordinate is prescribed (coordinate).
    pub joint: Option<Spanned<String>>,
    /// Index of the coordinate within the joint (coordinate).
    #[serde(default = "unlocated_zero")]
    pub coordinate: Spanned<usize>,
    /// The prescribed value, rad or m (coordinate; default the joint's q0).
    pub value: Option<Spanned<f64>>,
}

impl<'a> Validator<'a> {
    /// Ok when every constraint names a known kind, gives exactly the fields its kind reads,
    /// refers to bodies and joints that exist, and has finite, non-degenerate geometry.
    pub(super) fn check_constraints(&self, index_of: &BodyIndex<'a>) -> Result<(), super::SceneError> {
        for (i, spec) in self.scene.constraints.iter().enumerate() {
            let at = |field: &str| format!("constraint[{i}].{field}");
            let kind = spec.kind.get_ref().as_str();
            if !CONSTRAINT_KINDS.contains(&kind) {
                let message = format!("\"{kind}\" is not one of {CONSTRAINT_KINDS:?}");
                return Err(self.error(Some(spec.kind.span()), at("kind"), message));
            }
            self.check_constraint_fields(spec, kind, &at)?;
            for (end, field) in [(&spec.a, "a"), (&spec.b, "b")] {
                if let Some(name) = end {
                    self.check_body_or_ground(name, at(field), index_of)?;
                }
            }
            if let Some(joint) = &spec.joint {
                self.check_joint_name(joint, at("joint"))?;
                self.check_coordinate(joint, &spec.coordinate, at("coordinate"))?;
            }
            self.check_constraint_geometry(spec, &at)?;
        }
        Ok(())
    }

    /// Ok when the fields `kind` needs are present and no field of another kind is given.
    fn check_constraint_fields(
        &self,
        spec: &ConstraintSpec,
        kind: &str,
        at: &dyn Fn(&str) -> String,
    ) -> Result<(), super::SceneError> {
        let present = [
            ("a", spec.a.as_ref().map(|s| s.span())),
            ("b", spec.b.as_ref().map(|s| s.span())),
            ("directions", spec.directions.as_ref().map(|s| s.span())),
            ("normal", spec.normal.as_ref().map(|s| s.span())),
            ("length", spec.length.as_ref().map(|s| s.span())),
            ("joint", spec.joint.as_ref().map(|s| s.span())),
            ("value", spec.value.as_ref().map(|s| s.span())),
        ];
        let (required, allowed): (&[&str], &[&str]) = match kind {
            "points" => (&["a", "b"], &["a", "b", "directions"]),
            "plane" => (&["a", "normal"], &["a", "normal"]),
            "distance" => (&["a", "b", "length"], &["a", "b", "length"]),
            _ => (&["joint"], &["joint", "value"]),
        };
        for (field, span) in present {
            if span.is_none() && required.contains(&field) {
                let message = format!("a \"{kind}\" constraint needs `{field}`");
                return Err(self.error(Some(spec.kind.span()), at(field), message));
            }
            if span.is_some() && !allowed.contains(&field) {
                let message = format!("a \"{kind}\" constraint has no `{field}`");
                return Err(self.error(span, at(field), message));
            }
        }
        if kind == "plane" && spec.a.as_ref().is_some_and(|a| a.get_ref() == "ground") {
            let message = "the point held on a plane must be on a body, not the ground".to_string();
            return Err(self.error(spec.a.as_ref().map(|a| a.span()), at("a"), message));
        }
        if let (Some(a), Some(b)) = (&spec.a, &spec.b)
            && a.get_ref() == "ground"
            && b.get_ref() == "ground"
        {
            let message = "both ends are on the ground: the constraint involves no body".to_string();
            return Err(self.error(Some(b.span()), at("b"), message));
        }
        Ok(())
    }

    /// Ok when points, directions, normal, offset, length and value are finite, directions are
    /// one to three non-zero vectors, the normal is non-zero and the length positive.
    fn check_constraint_geometry(
        &self,
        spec: &ConstraintSpec,
        at: &dyn Fn(&str) -> String,
    ) -> Result<(), super::SceneError> {
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        let nonzero = |v: &[f64; 3]| finite(v) && v.iter().any(|x| *x != 0.0);
        let span = Some(spec.kind.span());
        if !finite(&spec.a_point) || !finite(&spec.b_point) || !spec.offset.is_finite() {
            let message = "points and offset must be finite numbers".to_string();
            return Err(self.error(span, at("a_point"), message));
        }
        if let Some(directions) = &spec.directions {
            let list = directions.get_ref();
            if !(1..=3).contains(&list.len()) || !list.iter().all(nonzero) {
                let message = format!("1 to 3 finite non-zero directions are needed, got {list:?}");
                return Err(self.error(Some(directions.span()), at("directions"), message));
            }
        }
        if let Some(normal) = &spec.normal
            && !nonzero(normal.get_ref())
        {
            let message = format!("the normal must be finite and non-zero, got {:?}", normal.get_ref());
            return Err(self.error(Some(normal.span()), at("normal"), message));
        }
        if let Some(length) = &spec.length
            && !(length.get_ref().is_finite() && *length.get_ref() > 0.0)
        {
            let message = format!("the length must be finite and > 0, got {}", length.get_ref());
            return Err(self.error(Some(length.span()), at("length"), message));
        }
        if let Some(value) = &spec.value
            && !value.get_ref().is_finite()
        {
            let message = format!("{} is not a finite number", value.get_ref());
            return Err(self.error(Some(value.span()), at("value"), message));
        }
        Ok(())
    }
}

impl Validator<'_> {
    /// Ok unless the scene has constraints and asks for an analysis that would ignore them.
    pub(super) fn check_constrained_analyses(&self) -> Result<(), super::SceneError> {
        let Some(first) = self.scene.constraints.first() else {
            return Ok(());
        };
        let analyses = &self.scene.analyses;
        let ignoring = [
            ("equilibrium", analyses.equilibrium.is_some()),
            ("modes", analyses.modes.is_some()),
            ("response", analyses.response.is_some()),
            ("impact", analyses.impact.is_some()),
        ];
        match ignoring.iter().find(|(_, asked)| *asked) {
            Some((name, _)) => Err(self.error(
                Some(first.kind.span()),
                format!("analyses.{name}"),
                "the scene has constraints, which only the dynamics analysis takes into account; \
                 use analyses.dynamics (with `equilibrium = true` for the constrained equilibrium)"
                    .to_string(),
            )),
            None => Ok(()),
        }
    }
}
