//! The error type of the mass crate.

use crate::validity::InertiaIssue;
use thiserror::Error;

/// What was wrong with which mass-properties input.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum MassError {
    /// A number that must be finite was NaN or infinite.
    #[error("{what} is not finite: {value}")]
    NonFinite {
        /// Which input held the value.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A mass that must be positive was zero or negative.
    #[error("mass must be positive, got {0}")]
    NonPositiveMass(f64),
    /// The mass from a density, density × measure, is below the smallest positive double: the
    /// body is too small (or too thin) for its mass to be represented.
    #[error(
        "the mass density × measure underflows to zero (density {density}, measure {measure}): the body is too small for a representable mass"
    )]
    MassUnderflow {
        /// The density given.
        density: f64,
        /// The body's length, area or volume (itself possibly rounded to zero).
        measure: f64,
    },
    /// A result would be NaN or infinite although every input is finite: it overflows the
    /// range of f64 (inputs of extreme magnitude).
    #[error("the {quantity} is not representable: it overflows the range of f64 (inputs of extreme magnitude)")]
    NonFiniteResult {
        /// Which output overflowed.
        quantity: &'static str,
    },
    /// A density (line, area or volume) that must be positive was zero or negative.
    #[error("density must be positive, got {0}")]
    NonPositiveDensity(f64),
    /// A length (radius, side, height) that must be positive was zero or negative.
    #[error("{what} must be positive, got {value}")]
    NonPositiveDimension {
        /// Which dimension.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// Dimensions that are each valid but inconsistent together (e.g. a torus whose tube
    /// radius exceeds its ring radius).
    #[error("inconsistent dimensions: {0}")]
    InconsistentDimensions(&'static str),
    /// A direction vector that must be non-zero was zero.
    #[error("{0} is the zero vector")]
    ZeroDirection(&'static str),
    /// A composite (sum, or body minus hole) has zero or negative total mass.
    #[error("total mass of the composite is {0}, must be positive")]
    NonPositiveTotalMass(f64),
    /// The inertia tensor is not physically valid; every problem found is listed.
    #[error("invalid inertia: {}", format_issues(.0))]
    InvalidInertia(Vec<InertiaIssue>),
    /// A mesh has no triangles (or none that is not degenerate).
    #[error("the mesh has no usable triangles")]
    EmptyMesh,
    /// A mesh vertex holds NaN or ±∞.
    #[error("vertex {vertex} has non-finite coordinate {value}")]
    NonFiniteVertex {
        /// Index of the vertex.
        vertex: usize,
        /// The offending coordinate.
        value: f64,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle {triangle} corner {corner} has index {index}, but there are only {vertex_count} vertices")]
    IndexOutOfRange {
        /// Index of the triangle.
        triangle: usize,
        /// Corner 0, 1 or 2.
        corner: usize,
        /// The offending vertex index.
        index: u64,
        /// Number of vertices.
        vertex_count: usize,
    },
    /// The mesh has more vertices than the topology check supports (2³¹).
    #[error("the mesh has {0} vertices; at most 2^31 are supported")]
    TooManyVertices(usize),
    /// The mesh has more triangles than the topology check supports (3n < 2³²).
    #[error("the mesh has {0} triangles; fewer than 2^32/3 are supported")]
    TooManyTriangles(usize),
    /// Degenerate (zero-area or repeated-index) triangles under a policy that rejects them.
    #[error("{count} degenerate triangles, the first is triangle {first}")]
    DegenerateTriangles {
        /// How many triangles are degenerate.
        count: usize,
        /// Index of the first one.
        first: usize,
    },
    /// A solid mesh is not closed, under a policy that rejects open meshes.
    #[error("the mesh is open: {boundary_edges} boundary edges, {non_manifold_edges} non-manifold edges")]
    OpenMesh {
        /// Edges used by exactly one triangle.
        boundary_edges: usize,
        /// Edges used by more than two triangles.
        non_manifold_edges: usize,
    },
    /// Neighbouring triangles of a closed mesh disagree about orientation.
    #[error(
        "the mesh is not consistently oriented: {misoriented_edges} edges are traversed twice in the same direction"
    )]
    InconsistentOrientation {
        /// Edges whose two triangles traverse them in the same direction.
        misoriented_edges: usize,
    },
    /// A closed mesh is inside out (negative signed volume) under a policy that rejects it.
    #[error("the mesh is inside out: signed volume {volume}")]
    InsideOut {
        /// The signed volume (negative).
        volume: f64,
    },
    /// A closed mesh encloses (numerically) no volume.
    #[error("the closed mesh encloses zero volume: {volume} (scale {scale})")]
    ZeroVolume {
        /// The signed volume found.
        volume: f64,
        /// The cube of the bounding-box diagonal, the scale it was compared against.
        scale: f64,
    },
    /// A weld tolerance that is negative, NaN or infinite.
    #[error("the weld tolerance must be finite and non-negative, got {0}")]
    InvalidWeldTolerance(f64),
    /// A weld tolerance so coarse that more than 64 distinct vertex positions lie in one cube
    /// of its size: welding would collapse the tessellation itself.
    #[error(
        "the weld tolerance {tolerance} is too coarse for this mesh: {positions} distinct vertices lie within one cube of that size"
    )]
    WeldTooCoarse {
        /// The absolute tolerance (m).
        tolerance: f64,
        /// Distinct positions found in one cube (the first count above the limit).
        positions: usize,
    },
    /// A slice argument has the wrong length.
    #[error("{what}: expected length {expected}, got {got}")]
    WrongLength {
        /// Which argument.
        what: &'static str,
        /// The required length.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// The mass properties of one body of a tree are unusable.
    #[error("body {body}: {error}")]
    Body {
        /// Index of the body in the tree.
        body: usize,
        /// What is wrong with its mass properties.
        error: Box<MassError>,
    },
    /// The kinematic tree or its workspace rejected a request.
    #[error(transparent)]
    Kinematics(#[from] mechanica_kinematics::KinematicsError),
    /// A mesh file could not be read.
    #[error("cannot read mesh file: {0}")]
    Io(String),
    /// A mesh file could not be parsed.
    #[error("cannot parse mesh file: {0}")]
    Parse(String),
}

fn format_issues(issues: &[InertiaIssue]) -> String {
    issues.iter().map(ToString::to_string).collect::<Vec<_>>().join("; ")
}

/// Fails with [`MassError::NonFinite`] unless `value` is finite.
pub(crate) fn check_finite(value: f64, what: &'static str) -> Result<f64, MassError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(MassError::NonFinite { what, value })
    }
}

/// Fails unless all entries of `values` are finite.
pub(crate) fn check_all_finite<'a>(
    values: impl IntoIterator<Item = &'a f64>,
    what: &'static str,
) -> Result<(), MassError> {
    match values.into_iter().copied().find(|v| !v.is_finite()) {
        Some(value) => Err(MassError::NonFinite { what, value }),
        None => Ok(()),
    }
}

/// Fails with [`MassError::NonFiniteResult`] naming `quantity` unless every computed value is
/// finite.
pub(crate) fn check_result<'a>(
    values: impl IntoIterator<Item = &'a f64>,
    quantity: &'static str,
) -> Result<(), MassError> {
    if values.into_iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(MassError::NonFiniteResult { quantity })
    }
}

/// Fails unless `value` is a finite, strictly positive length.
pub(crate) fn check_dimension(value: f64, what: &'static str) -> Result<f64, MassError> {
    check_finite(value, what)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(MassError::NonPositiveDimension { what, value })
    }
}
