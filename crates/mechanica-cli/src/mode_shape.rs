//! The geometry of the mode-shape pictures: the mechanism's skeleton (body origins, which are
//! the joint origins of revolute and spherical joints, and centres of mass) at the configuration
//! q₀ of the modes, and displaced along each mode x_k to q₀ + s·x_k by exact forward
//! kinematics. The amplitude s makes the largest linearised displacement of a drawn point
//! [`DISPLACEMENT_FRACTION`] of the mechanism's extent, unless a body would then turn by more
//! than [`MAX_ROTATION`] rad (a light link spinning about its own axis): s is then smaller, and
//! the figure names that body.

use crate::mode_record::{ModeKindName, ModeRecord};
use crate::report::text::{bound, number};
use mechanica::kinematics::nalgebra::Vector3;
use mechanica::kinematics::tree::KinematicTree;
use mechanica::mass::MassProperties;

/// The largest displacement of a drawn point, as a fraction of the mechanism's extent.
pub const DISPLACEMENT_FRACTION: f64 = 0.12;

/// The largest rotation of a body in a drawn shape, rad: beyond it the exact pose no longer
/// looks like the linear mode.
pub const MAX_ROTATION: f64 = 0.5;

/// Positions of the drawn points, world frame, m.
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    /// Each body's origin: where its joint places it.
    pub origins: Vec<Vector3<f64>>,
    /// Each body's centre of mass; `None` for a massless body.
    pub centres: Vec<Option<Vector3<f64>>>,
}

impl Pose {
    /// Every point of the pose.
    pub fn points(&self) -> impl Iterator<Item = &Vector3<f64>> {
        self.origins.iter().chain(self.centres.iter().flatten())
    }
}

/// The mechanism at rest: its tree structure and pose, and where "up" is.
#[derive(Debug, Clone)]
pub struct Skeleton {
    /// Each body's name.
    pub names: Vec<String>,
    /// Each body's parent body (`None`: hung from the ground).
    pub parents: Vec<Option<usize>>,
    /// Whether each body's joint has coordinates (a fixed joint has none).
    pub moving: Vec<bool>,
    /// The ground point the root hangs from, m.
    pub base: Vector3<f64>,
    /// The world's up direction (against gravity; z without gravity), unit.
    pub up: Vector3<f64>,
    /// The pose at q₀.
    pub rest: Pose,
    /// The diagonal of the bounding box of the rest pose and the base, m (1 m when that box
    /// is a point).
    pub extent: f64,
}

/// One mode drawn on the skeleton.
#[derive(Debug, Clone)]
pub struct ModeFigure {
    /// The mode's number in the report (from 1).
    pub number: usize,
    /// Its class.
    pub kind: ModeKindName,
    /// Two heading lines: number and class; frequency with its certified interval.
    pub heading: [String; 2],
    /// The pose at q₀ + s·x, when it could be drawn.
    pub displaced: Option<Pose>,
    /// The amplitude s.
    pub amplitude: f64,
    /// The largest distance a drawn point moved, m.
    pub largest: f64,
    /// The body whose rotation limited s, when [`MAX_ROTATION`] did.
    pub turned_most: Option<usize>,
    /// The body whose origin or centre of mass moved [`ModeFigure::largest`].
    pub moved_most: Option<usize>,
    /// Why no displaced pose is drawn.
    pub note: Option<String>,
}

/// The mode-shape pictures of a mechanism.
#[derive(Debug, Clone)]
pub struct ModeShapes {
    /// The mechanism at rest.
    pub skeleton: Skeleton,
    /// The modes drawn.
    pub modes: Vec<ModeFigure>,
}

/// The pose of `tree` at `q`.
fn pose_at(tree: &KinematicTree, bodies: &[MassProperties], q: &[f64]) -> Result<Pose, String> {
    let mut ws = tree.workspace();
    tree.update_positions(&mut ws, q).map_err(|e| e.to_string())?;
    let mut pose = Pose {
        origins: Vec::with_capacity(bodies.len()),
        centres: Vec::with_capacity(bodies.len()),
    };
    for (i, body) in bodies.iter().enumerate() {
        pose.origins.push(ws.position(i).map_err(|e| e.to_string())?);
        let centre = (body.mass > 0.0).then(|| ws.point_position(i, &body.p_oc));
        pose.centres.push(centre.transpose().map_err(|e| e.to_string())?);
    }
    Ok(pose)
}

/// The skeleton of `tree` with `bodies` (named `names`) at `q`; `gravity` sets the up
/// direction.
pub fn skeleton(
    tree: &KinematicTree,
    bodies: &[MassProperties],
    names: &[String],
    q: &[f64],
    gravity: Option<[f64; 3]>,
) -> Result<Skeleton, String> {
    let rest = pose_at(tree, bodies, q)?;
    let base = Vector3::zeros();
    let (lo, hi) = rest.points().fold((base, base), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
    let extent = (hi - lo).norm();
    let up = gravity
        .map(|g| -Vector3::from(g))
        .filter(|g| g.norm() > 0.0 && g.norm().is_finite())
        .map_or(Vector3::z(), |g| g.normalize());
    Ok(Skeleton {
        names: names.to_vec(),
        parents: tree.parents().to_vec(),
        moving: (0..bodies.len()).map(|i| !tree.dof_range(i).is_empty()).collect(),
        base,
        up,
        rest,
        extent: if extent > 0.0 && extent.is_finite() {
            extent
        } else {
            1.0
        },
    })
}

/// The largest linearised displacement of a drawn point, and the largest body rotation with
/// that body, per unit amplitude of the mode `x`, from the point and angular Jacobians at `q`.
fn linear_motion(
    tree: &KinematicTree,
    bodies: &[MassProperties],
    q: &[f64],
    x: &[f64],
) -> Result<(f64, (f64, usize)), String> {
    let mut ws = tree.workspace();
    tree.update_positions(&mut ws, q).map_err(|e| e.to_string())?;
    let n = tree.dof();
    let mut jacobian = vec![0.0; 3 * n];
    let times_x = |j: &[f64]| -> f64 {
        let v: Vector3<f64> = (0..n)
            .map(|k| Vector3::new(j[3 * k], j[3 * k + 1], j[3 * k + 2]) * x[k])
            .sum();
        v.norm()
    };
    let (mut displacement, mut rotation) = (0.0f64, (0.0f64, 0));
    for (i, body) in bodies.iter().enumerate() {
        let mut points = vec![Vector3::zeros()];
        if body.mass > 0.0 {
            points.push(body.p_oc);
        }
        for p in &points {
            tree.point_jacobian(&ws, i, p, &mut jacobian)
                .map_err(|e| e.to_string())?;
            displacement = displacement.max(times_x(&jacobian));
        }
        tree.angular_jacobian(&ws, i, &mut jacobian)
            .map_err(|e| e.to_string())?;
        let turn = times_x(&jacobian);
        if turn > rotation.0 {
            rotation = (turn, i);
        }
    }
    Ok((displacement, rotation))
}

/// The figure of mode `number` with record `record` and shape `x` on `skeleton`.
pub fn figure(
    tree: &KinematicTree,
    bodies: &[MassProperties],
    q: &[f64],
    skeleton: &Skeleton,
    number: usize,
    record: &ModeRecord,
    x: &[f64],
) -> ModeFigure {
    let mut figure = ModeFigure {
        number,
        kind: record.kind,
        heading: heading(number, record),
        displaced: None,
        amplitude: 0.0,
        largest: 0.0,
        turned_most: None,
        moved_most: None,
        note: None,
    };
    match displaced_pose(tree, bodies, q, skeleton, x) {
        Ok((pose, s, turned_most)) => {
            figure.turned_most = turned_most;
            (figure.moved_most, figure.largest) = moved_most(&skeleton.rest, &pose);
            figure.amplitude = s;
            figure.displaced = Some(pose);
        }
        Err(why) => figure.note = Some(why),
    }
    figure
}

/// The body whose centre of mass (or origin) lies farthest from its place in `rest`, and that
/// distance, m. Centres come first: a body's origin is its joint, which it shares with its
/// parent, so a tie goes to the body whose mass is there.
fn moved_most(rest: &Pose, moved: &Pose) -> (Option<usize>, f64) {
    let origins = rest
        .origins
        .iter()
        .zip(&moved.origins)
        .map(|(a, b)| Some((a - b).norm()));
    let centres = rest.centres.iter().zip(&moved.centres).map(|(a, b)| match (a, b) {
        (Some(a), Some(b)) => Some((a - b).norm()),
        _ => None,
    });
    let mut best = (None, 0.0);
    for (body, distance) in centres.enumerate().chain(origins.enumerate()) {
        if let Some(d) = distance.filter(|d| *d > best.1) {
            best = (Some(body), d);
        }
    }
    best
}

/// The pose at q + s·x, the amplitude s (see the module docs) and the body whose rotation
/// limited s, if one did.
fn displaced_pose(
    tree: &KinematicTree,
    bodies: &[MassProperties],
    q: &[f64],
    skeleton: &Skeleton,
    x: &[f64],
) -> Result<(Pose, f64, Option<usize>), String> {
    if x.len() != q.len() || x.iter().any(|v| !v.is_finite()) {
        return Err("no finite shape vector for this mode".into());
    }
    let (displacement, (rotation, turning)) = linear_motion(tree, bodies, q, x)?;
    if displacement.is_nan() || displacement <= 0.0 {
        return Err("this mode moves none of the drawn points".into());
    }
    let by_displacement = DISPLACEMENT_FRACTION * skeleton.extent / displacement;
    let by_rotation = MAX_ROTATION / rotation;
    let (s, turned_most) = if by_rotation < by_displacement {
        (by_rotation, Some(turning))
    } else {
        (by_displacement, None)
    };
    let moved: Vec<f64> = q.iter().zip(x).map(|(a, b)| a + s * b).collect();
    let pose = pose_at(tree, bodies, &moved).map_err(|e| format!("displaced shape: {e}"))?;
    Ok((pose, s, turned_most))
}

/// The frequency |ω|/2π (Hz) of ω² and the ends of its interval from ω² ± bound.
fn hertz_interval(omega_sq: f64, bound: f64) -> [f64; 3] {
    let hz = |w2: f64| w2.max(0.0).sqrt() / std::f64::consts::TAU;
    let w2 = omega_sq.abs();
    [hz(w2), hz(w2 - bound), hz(w2 + bound)]
}

/// `x` rounded to `digits` significant digits towards −∞ (`up` false) or +∞ (`up` true).
fn rounded_outward(x: f64, digits: usize, up: bool) -> String {
    if x == 0.0 || !x.is_finite() {
        return number(x, digits);
    }
    let unit = 10f64.powf(x.abs().log10().floor() + 1.0 - digits as f64);
    let k = if up { (x / unit).ceil() } else { (x / unit).floor() };
    number(k * unit, digits)
}

/// `[value, lo, hi]` printed with enough digits to tell lo from hi (at most ten), the ends
/// rounded outwards so that the printed interval contains [lo, hi].
fn interval_text(values: [f64; 3], unit: &str, name: &str) -> String {
    let [v, lo, hi] = values;
    let digits = if hi > lo && v > 0.0 {
        ((v / (hi - lo)).log10().ceil() + 1.0).clamp(2.0, 10.0) as usize
    } else {
        10
    };
    format!(
        "{name} = {} {unit}, certified in [{}, {}] {unit}",
        number(v, digits),
        rounded_outward(lo, digits, false),
        rounded_outward(hi, digits, true)
    )
}

/// A small number with two significant digits (0 as "0").
fn short(value: f64) -> String {
    if value == 0.0 { "0".into() } else { bound(value) }
}

/// The two heading lines of mode `number`.
pub fn heading(number: usize, record: &ModeRecord) -> [String; 2] {
    let mut first = format!("mode {number} · {}", record.kind.as_str());
    if record.multiplicity > 1 {
        first.push_str(&format!(" · multiplicity {}", record.multiplicity));
    }
    let w2 = record.omega_sq.unwrap_or(f64::INFINITY);
    let second = match record.kind {
        ModeKindName::Oscillatory => interval_text(hertz_interval(w2, record.bound), "Hz", "f"),
        ModeKindName::Unstable => {
            let [_, lo, hi] = hertz_interval(w2, record.bound).map(|f| f * std::f64::consts::TAU);
            let gamma = record.growth_rate.unwrap_or(f64::NAN);
            interval_text([gamma, lo, hi], "1/s", "growth rate γ")
        }
        ModeKindName::Zero => format!(
            "rigid-body motion: ω² = {} ± {} rad²/s²",
            short(w2),
            short(record.bound)
        ),
        ModeKindName::Undecided => format!(
            "ω² = {} ± {} rad²/s²: the interval contains 0",
            short(w2),
            short(record.bound)
        ),
        ModeKindName::Infinite => "a massless direction: ω² = +∞".to_string(),
    };
    [first, second]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The printed interval of a mode near 1 Hz contains the certified one, is at most a few
    /// times wider (or ten digits wide), and f is printed to within the interval's width.
    #[test]
    fn headings_state_the_certified_interval() {
        let w2 = std::f64::consts::TAU.powi(2);
        for relative in [1e-3, 1e-6, 1e-9, 1e-13] {
            let [f, lo, hi] = hertz_interval(w2 * 1.0001, relative * w2);
            let text = interval_text([f, lo, hi], "Hz", "f");
            let numbers: Vec<f64> = text
                .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == 'e' || c == '-'))
                .filter_map(|t| t.parse().ok())
                .collect();
            assert_eq!(numbers.len(), 3, "{text}");
            assert!(numbers[1] <= lo && hi <= numbers[2], "{text} vs [{lo}, {hi}]");
            assert!((numbers[0] - f).abs() <= (hi - lo).max(1e-9 * f), "{text} vs {f}");
            assert!(numbers[2] - numbers[1] <= 3.0 * (hi - lo) + 2e-9 * f, "{text} too wide");
        }
    }
}
