//! Mesh loaders: STL (binary and ASCII, through `stl_io`) and Wavefront OBJ (through `tobj`).
//! The readers ([`read_stl`], [`read_obj`], [`load_stl`], [`load_obj`]) merge identical vertex
//! positions; [`load_mesh`] and [`load_mesh_welded`] also weld vertices within a tolerance
//! relative to the mesh's size ([`crate::weld`], by default [`DEFAULT_WELD_TOLERANCE`] of the
//! bounding-box diagonal), so that closed meshes with hairline cracks between their patches
//! come out closed for [`crate::mesh::mesh_topology`].

use crate::MassError;
use crate::mesh::TriangleMesh;
use crate::weld::{DEFAULT_WELD_TOLERANCE, WeldReport, weld_vertices};
use std::collections::HashMap;
use std::io::{BufRead, Read, Seek};
use std::path::Path;

/// Reads an STL mesh (binary or ASCII, detected from the content) from `reader`.
pub fn read_stl<R: Read + Seek>(reader: &mut R) -> Result<TriangleMesh, MassError> {
    let mesh = stl_io::read_stl(reader).map_err(|e| MassError::Parse(format!("STL: {e}")))?;
    let vertices = mesh
        .vertices
        .iter()
        .map(|v| [f64::from(v.0[0]), f64::from(v.0[1]), f64::from(v.0[2])])
        .collect();
    let mut triangles = Vec::with_capacity(mesh.faces.len());
    for (i, f) in mesh.faces.iter().enumerate() {
        let mut t = [0u32; 3];
        for k in 0..3 {
            t[k] = u32::try_from(f.vertices[k])
                .map_err(|_| MassError::Parse(format!("STL: triangle {i} has vertex index beyond u32")))?;
        }
        triangles.push(t);
    }
    Ok(TriangleMesh { vertices, triangles })
}

/// Reads an STL file, see [`read_stl`].
pub fn load_stl(path: impl AsRef<Path>) -> Result<TriangleMesh, MassError> {
    let path = path.as_ref();
    let mut file = std::fs::File::open(path).map_err(|e| MassError::Io(format!("{}: {e}", path.display())))?;
    read_stl(&mut file)
}

fn obj_options() -> tobj::LoadOptions {
    tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    }
}

/// Joins all models into one mesh, merging bitwise-identical positions (OBJ files often repeat
/// positions per group or object, which would otherwise look like open seams).
fn from_models(models: Vec<tobj::Model>) -> Result<TriangleMesh, MassError> {
    let mut mesh = TriangleMesh::default();
    let mut index_of: HashMap<[u64; 3], u32> = HashMap::new();
    for model in models {
        let m = model.mesh;
        let mut local = Vec::with_capacity(m.positions.len() / 3);
        for p in m.positions.chunks_exact(3) {
            let key = [p[0].to_bits(), p[1].to_bits(), p[2].to_bits()];
            let next = u32::try_from(mesh.vertices.len())
                .map_err(|_| MassError::Parse("OBJ: more than 2^32 vertices".to_string()))?;
            let index = *index_of.entry(key).or_insert(next);
            if index == next {
                mesh.vertices.push([p[0], p[1], p[2]]);
            }
            local.push(index);
        }
        for (i, t) in m.indices.chunks_exact(3).enumerate() {
            let mut tri = [0u32; 3];
            for k in 0..3 {
                tri[k] = *local.get(t[k] as usize).ok_or_else(|| {
                    MassError::Parse(format!("OBJ: face {i} refers to position {} that does not exist", t[k]))
                })?;
            }
            mesh.triangles.push(tri);
        }
    }
    Ok(mesh)
}

/// Reads a Wavefront OBJ mesh from `reader` (all objects and groups into one mesh; polygons
/// are triangulated as fans, materials are ignored).
pub fn read_obj<R: BufRead>(reader: &mut R) -> Result<TriangleMesh, MassError> {
    let (models, _materials) = tobj::load_obj_buf(reader, &obj_options(), |_| Err(tobj::LoadError::OpenFileFailed))
        .map_err(|e| MassError::Parse(format!("OBJ: {e}")))?;
    from_models(models)
}

/// Reads an OBJ file, see [`read_obj`].
pub fn load_obj(path: impl AsRef<Path>) -> Result<TriangleMesh, MassError> {
    let path = path.as_ref();
    let file = std::fs::File::open(path).map_err(|e| MassError::Io(format!("{}: {e}", path.display())))?;
    read_obj(&mut std::io::BufReader::new(file))
}

/// Reads a mesh file, choosing the format from the extension (`.stl` or `.obj`, any case),
/// and welds its vertices within [`DEFAULT_WELD_TOLERANCE`] of its bounding-box diagonal
/// (see [`load_mesh_welded`] for another tolerance and the weld report).
pub fn load_mesh(path: impl AsRef<Path>) -> Result<TriangleMesh, MassError> {
    load_mesh_welded(path, DEFAULT_WELD_TOLERANCE).map(|(mesh, _)| mesh)
}

/// Reads a mesh file as [`load_mesh`] does, welding its vertices within `relative_tolerance`
/// × its bounding-box diagonal (0 merges identical positions only), and reports the welding.
///
/// Errors: those of the readers and of [`weld_vertices`].
pub fn load_mesh_welded(
    path: impl AsRef<Path>,
    relative_tolerance: f64,
) -> Result<(TriangleMesh, WeldReport), MassError> {
    weld_vertices(&load_mesh_unwelded(path.as_ref())?, relative_tolerance)
}

/// The mesh file as read, identical positions merged.
fn load_mesh_unwelded(path: &Path) -> Result<TriangleMesh, MassError> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("stl") => load_stl(path),
        Some("obj") => load_obj(path),
        _ => Err(MassError::Parse(format!(
            "{}: unknown mesh format (expected .stl or .obj)",
            path.display()
        ))),
    }
}
