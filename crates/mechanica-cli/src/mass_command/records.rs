//! The records of `mechanica mass`: the mesh read and welded, its mass properties, and what
//! the mesh checks found.

use crate::report::text::{Precision, Text, bound};
use serde::Serialize;

/// What welding did, in the units of the scaled mesh.
#[derive(Debug, Clone, Serialize)]
pub struct WeldRecord {
    /// The tolerance relative to the bounding-box diagonal.
    pub relative_tolerance: f64,
    /// The tolerance, m.
    pub tolerance: f64,
    /// Vertices welded into another.
    pub vertices_welded: usize,
    /// Triangles collapsed by welding, dropped.
    pub triangles_dropped: usize,
    /// Largest vertex displacement by welding, m.
    pub max_displacement: f64,
}

/// A mesh file read.
#[derive(Debug, Clone, Serialize)]
pub struct MeshLoadRecord {
    /// Vertices after welding.
    pub vertices: usize,
    /// Triangles.
    pub triangles: usize,
    /// m per file unit.
    pub scale: f64,
    /// The welding.
    pub weld: WeldRecord,
}

impl MeshLoadRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        out.count("vertices (after welding)", self.vertices);
        out.count("triangles", self.triangles);
        out.value("coordinate scale", self.scale, "m per file unit", Precision::Exact);
        let w = &self.weld;
        out.value(
            "weld tolerance (relative to bounding-box diagonal)",
            w.relative_tolerance,
            "",
            Precision::Exact,
        );
        out.value("weld tolerance", w.tolerance, "m", Precision::Exact);
        out.count("vertices welded into another", w.vertices_welded);
        out.count("triangles collapsed by welding, dropped", w.triangles_dropped);
        out.value(
            "largest vertex displacement by welding",
            w.max_displacement,
            "m",
            Precision::Exact,
        );
    }
}

/// The mass model of a mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MeshModelName {
    /// A solid of uniform volume density.
    Solid,
    /// A thin shell of uniform surface density.
    Shell,
}

/// The six independent entries of an inertia tensor, as URDF's `<inertia>` takes them.
#[derive(Debug, Clone, Serialize)]
pub struct InertiaSix {
    /// J_xx.
    pub ixx: f64,
    /// J_xy.
    pub ixy: f64,
    /// J_xz.
    pub ixz: f64,
    /// J_yy.
    pub iyy: f64,
    /// J_yz.
    pub iyz: f64,
    /// J_zz.
    pub izz: f64,
}

/// The mass properties of a mesh, in the file's frame (scaled to m).
#[derive(Debug, Clone, Serialize)]
pub struct MeshMassRecord {
    /// Solid or shell.
    pub model: MeshModelName,
    /// Mass, kg.
    pub mass: f64,
    /// Volume (m³, solid) or surface area (m², shell).
    pub measure: f64,
    /// Density, kg/m³ (solid) or kg/m² (shell).
    pub density: f64,
    /// Centre of mass, m.
    pub centre_of_mass: [f64; 3],
    /// Inertia tensor about the centre of mass, rows, kg·m².
    pub inertia: [[f64; 3]; 3],
    /// The same as URDF's six entries.
    pub inertia_urdf: InertiaSix,
    /// Inertia tensor about the file's origin, rows, kg·m².
    pub inertia_about_origin: [[f64; 3]; 3],
    /// Principal moments I1 ≤ I2 ≤ I3, kg·m².
    pub principal_moments: [f64; 3],
    /// Principal axes, one unit vector per moment, right-handed.
    pub principal_axes: [[f64; 3]; 3],
    /// ‖RᵀJR − diag‖ / ‖J‖.
    pub principal_relative_residual: f64,
    /// Relative rounding-error bound of the volume integrals.
    pub relative_error_bound: f64,
}

impl MeshMassRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        let relative = Precision::Relative(self.relative_error_bound);
        let (measure, unit, density) = match self.model {
            MeshModelName::Solid => ("volume", "m³", "kg/m³"),
            MeshModelName::Shell => ("surface area", "m²", "kg/m²"),
        };
        out.value("mass", self.mass, "kg", relative);
        out.value(measure, self.measure, unit, relative);
        out.value("density", self.density, density, Precision::Exact);
        // Moments and the centre are accurate relative to the body's scale, not entrywise.
        let size = self.inertia.iter().flatten().fold(0.0, |a: f64, b| a.max(b.abs()));
        let moment = Precision::Absolute(self.relative_error_bound * size);
        // The body's scale: the larger of its distance from the origin and its radius of gyration.
        let gyration = if self.mass > 0.0 {
            (size / self.mass).sqrt()
        } else {
            0.0
        };
        let reach = self.centre_of_mass.iter().fold(gyration, |a: f64, b| a.max(b.abs()));
        let centre = Precision::Absolute(self.relative_error_bound * reach);
        out.values("centre of mass (file frame)", &self.centre_of_mass, "m", centre);
        out.values(
            "inertia about centre of mass (rows of 3×3)",
            self.inertia.as_flattened(),
            "kg·m²",
            moment,
        );
        let j = &self.inertia_urdf;
        let six = [j.ixx, j.ixy, j.ixz, j.iyy, j.iyz, j.izz];
        out.values("inertia about c.o.m. ixx ixy ixz iyy iyz izz", &six, "kg·m²", moment);
        let origin = self.inertia_about_origin.as_flattened();
        out.values(
            "inertia about file origin (rows of 3×3)",
            origin,
            "kg·m²",
            Precision::Exact,
        );
        let residual = Precision::Absolute(self.principal_relative_residual.max(self.relative_error_bound) * size);
        out.values(
            "principal moments I1 ≤ I2 ≤ I3",
            &self.principal_moments,
            "kg·m²",
            residual,
        );
        let axes = self.principal_axes.as_flattened();
        out.values("principal axes (axis 1, axis 2, axis 3)", axes, "", Precision::Exact);
        out.line(
            "accuracy",
            &format!("relative rounding-error bound {}", bound(self.relative_error_bound)),
        );
    }
}

/// What the mesh checks found.
#[derive(Debug, Clone, Serialize)]
pub struct MeshDiagnosticsRecord {
    /// Triangles.
    pub triangles: usize,
    /// Degenerate triangles skipped.
    pub degenerate_triangles: usize,
    /// Edges used by one triangle.
    pub boundary_edges: usize,
    /// Edges used by more than two triangles.
    pub non_manifold_edges: usize,
    /// Edges whose two triangles disagree in orientation.
    pub misoriented_edges: usize,
    /// The mesh was inside out and its orientation was flipped.
    pub flipped: bool,
}

impl MeshDiagnosticsRecord {
    pub(crate) fn write_text(&self, out: &mut Text) {
        out.count("triangles", self.triangles);
        out.count("degenerate triangles skipped", self.degenerate_triangles);
        out.count("boundary edges (used by one triangle)", self.boundary_edges);
        out.count("non-manifold edges (used by > 2 triangles)", self.non_manifold_edges);
        out.count("misoriented edges", self.misoriented_edges);
        out.line(
            "inside out, orientation flipped",
            if self.flipped { "yes" } else { "no" },
        );
    }
}
