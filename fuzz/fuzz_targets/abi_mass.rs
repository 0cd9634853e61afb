//! The mass-properties C ABI: a sequence of calls with arbitrary numbers, each held to the
//! output contract (`oracle`) and to an invariant from an independent computation: a rigid
//! motion undone restores the body; combining then subtracting a part restores the rest;
//! Steiner's theorem, the moment about a line, the kinetic energy and the angular momentum
//! match their formulas; the principal axes rebuild the tensor; closed-form primitives match
//! the textbook moments; a repaired tensor passes the check; a mesh moved rigidly has the
//! moved mass properties; on a tree, T = ½ q̇ᵀ A q̇ with A from mech_tree_mass_matrix.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mechanica::ffi::*;
use mechanica_fuzz::input::{mat_vec, rotate_tensor, rotation_of};
use mechanica_fuzz::oracle::{
    Sentinel, binary_exponent, check_outputs, check_status, doubles_of, doubles_untouched, sentinel_doubles,
    times_power_of_two,
};
use mechanica_fuzz::tree::{body_properties, build_tree, v3};
use mechanica_fuzz::{Input, trace};

type Props = mech_mass_properties_t;

fn arr(v: &mech_vec3_t) -> [f64; 3] {
    [v.x, v.y, v.z]
}

fn norm1(a: &[f64]) -> f64 {
    a.iter().map(|x| x.abs()).sum()
}

/// The exponent e with 2ᵉ ≤ max|aᵢ| < 2ᵉ⁺¹ (0 for a zero or non-finite array).
fn largest_exponent(a: &[f64]) -> i32 {
    binary_exponent(a.iter().fold(0.0f64, |m, x| m.max(x.abs())))
}

/// a·b, but 0 when either is 0: a zero inertia times an overflowing ω² contributes nothing
/// to a tolerance (0·∞ would make it NaN).
fn weighted(a: f64, b: f64) -> f64 {
    if a == 0.0 || b == 0.0 { 0.0 } else { a * b }
}

fn diagonal(d: f64) -> [f64; 9] {
    [d, 0.0, 0.0, 0.0, d, 0.0, 0.0, 0.0, d]
}

/// xᵀ M x with M and x first scaled by exact powers of two to order one, so that no
/// intermediate product leaves the normal range; one rounding of the unscaled result remains.
fn scaled_quadratic_form(m: &[f64; 9], x: [f64; 3]) -> f64 {
    let (em, ex) = (largest_exponent(m), largest_exponent(&x));
    let ms = m.map(|v| times_power_of_two(v, -em));
    let xs = x.map(|v| times_power_of_two(v, -ex));
    let mx = mat_vec(&ms, xs);
    let form = xs[0] * mx[0] + xs[1] * mx[1] + xs[2] * mx[2];
    times_power_of_two(form, em + 2 * ex)
}

/// Calls `f` with a sentinel output and applies the output contract.
fn call<T: Copy>(name: &str, f: impl FnOnce(*mut T) -> mech_status_t) -> Option<T>
where
    T: AsDoubles,
{
    let mut out = Sentinel::<T>::new();
    let status = f(out.ptr());
    check_outputs(name, status, out.untouched(), out.value.doubles());
    (status == MECH_STATUS_OK).then_some(out.value)
}

trait AsDoubles {
    fn doubles(&self) -> &[f64];
}
impl AsDoubles for Props {
    fn doubles(&self) -> &[f64] {
        doubles_of(self)
    }
}
impl AsDoubles for mech_vec3_t {
    fn doubles(&self) -> &[f64] {
        doubles_of(self)
    }
}
impl AsDoubles for mech_mat3_t {
    fn doubles(&self) -> &[f64] {
        &self.m
    }
}
impl AsDoubles for f64 {
    fn doubles(&self) -> &[f64] {
        std::slice::from_ref(self)
    }
}

/// Size of a body's numbers: mass, |centre|, ‖J‖₁.
fn scale_of(p: &Props) -> (f64, f64, f64) {
    (
        p.mass.abs(),
        norm1(doubles_of(&p.center_of_mass)),
        norm1(&p.inertia_about_com.m),
    )
}

fn close(a: &[f64], b: &[f64], tolerance: f64) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tolerance)
}

/// x ↦ R x + t followed by its inverse gives the body back.
fn transform_round_trip(input: &mut Input) {
    let p = body_properties(input);
    let q = input.unit_quaternion();
    let rotation = mech_quat_t {
        w: q[0],
        x: q[1],
        y: q[2],
        z: q[3],
    };
    let t = if input.bool() {
        input.vec3_moderate(10.0)
    } else {
        input.vec3_any()
    };
    let Some(moved) = call::<Props>("mech_mass_transform", |out| unsafe {
        mech_mass_transform(&p, &rotation, &v3(t), out)
    }) else {
        return;
    };
    let r = rotation_of(q);
    let expected_com = mat_vec(&r, arr(&p.center_of_mass));
    let (_, c, j) = scale_of(&p);
    // Plus the subnormal spacing that rotating a centre near 1e-310 rounds to.
    let position_tol = 1e-14 * (c + norm1(&t)) + 16.0 * f64::from_bits(1);
    for k in 0..3 {
        assert!(
            (arr(&moved.center_of_mass)[k] - expected_com[k] - t[k]).abs() <= position_tol,
            "moved centre: {:?} vs R c + t = {:?} + {t:?} (tolerance {position_tol:e})",
            arr(&moved.center_of_mass),
            expected_com
        );
    }
    let jm = p.inertia_about_com.m;
    if (0..9).any(|k| (jm[k] - jm[(k % 3) * 3 + k / 3]).abs() > 1e-12 * j) {
        return; // refused or not, an asymmetric tensor is outside this oracle
    }
    // A tensor symmetric within the validity tolerance is used by its symmetric part.
    let sym: [f64; 9] = std::array::from_fn(|k| 0.5 * jm[k] + 0.5 * jm[(k % 3) * 3 + k / 3]);
    let want = rotate_tensor(&r, &sym);
    // 1e-14·j underflows for subnormal tensors, and the oracle's own halving of a subnormal
    // rounds away a spacing: allow eight spacings, as the mass crate's validity check does.
    let subnormal_floor = 8.0 * f64::from_bits(1);
    assert!(
        close(&moved.inertia_about_com.m, &want, 1e-14 * j + subnormal_floor),
        "R J Rᵀ: {:?} vs {want:?} for J = {:?}",
        moved.inertia_about_com.m,
        p.inertia_about_com.m
    );
    assert_eq!(moved.mass, p.mass);
}

/// combine(a, moved b) then subtract(moved b) gives a back.
fn combine_subtract(input: &mut Input) {
    let a = body_properties(input);
    let b = body_properties(input);
    let q = input.unit_quaternion();
    let rotations = [
        mech_quat_t {
            w: 1.0,
            x: 0.0,
            y: 0.0,
            z: 0.0,
        },
        mech_quat_t {
            w: q[0],
            x: q[1],
            y: q[2],
            z: q[3],
        },
    ];
    let translations = [v3([0.0; 3]), v3(input.vec3_moderate(2.0))];
    let parts = [a, b];
    let Some(sum) = call::<Props>("mech_mass_combine", |out| unsafe {
        mech_mass_combine(parts.as_ptr(), rotations.as_ptr(), translations.as_ptr(), 2, out)
    }) else {
        return;
    };
    let Some(hole) = call::<Props>("mech_mass_transform", |out| unsafe {
        mech_mass_transform(&b, &rotations[1], &translations[1], out)
    }) else {
        panic!("a part that combined could not be moved");
    };
    assert!(
        (sum.mass - (a.mass + b.mass)).abs() <= 1e-15 * sum.mass,
        "masses do not add"
    );
    let Some(rest) = call::<Props>("mech_mass_subtract", |out| unsafe {
        mech_mass_subtract(&sum, &hole, out)
    }) else {
        return;
    };
    // Subtraction cancels: errors grow like the whole over the remainder. The stored total
    // mass carries a rounding of u·M, which is relative u·M/m_a in the remainder's mass and
    // moves the recovered centre by that fraction of its own distance |c_a − c_sum|; so the
    // reach includes the first body's centre as well as the sum's and the hole's.
    let amplification = sum.mass / a.mass;
    if !(amplification < 1e6) {
        return;
    }
    let (m, c, _) = scale_of(&sum);
    let reach = c + norm1(doubles_of(&hole.center_of_mass)) + norm1(doubles_of(&a.center_of_mass)) + 1.0;
    let j = norm1(&sum.inertia_about_com.m) + m * reach * reach;
    let tol = 1e-12 * amplification;
    assert!(
        (rest.mass - a.mass).abs() <= tol * m,
        "mass: {} back as {}",
        a.mass,
        rest.mass
    );
    assert!(
        close(
            doubles_of(&rest.center_of_mass),
            doubles_of(&a.center_of_mass),
            tol * reach
        ),
        "centre not restored: {:?} back as {:?} (tolerance {:e}; whole {sum:?}, part {hole:?})",
        arr(&a.center_of_mass),
        arr(&rest.center_of_mass),
        tol * reach
    );
    assert!(
        // Tensors at the subnormal spacing (bodies of subnormal mass) round by whole steps.
        close(
            &rest.inertia_about_com.m,
            &a.inertia_about_com.m,
            tol * j + 16.0 * f64::from_bits(1)
        ),
        "tensor not restored: {:?} back as {:?} (tolerance {:e}; whole {sum:?}, part {hole:?}, first {a:?})",
        a.inertia_about_com.m,
        rest.inertia_about_com.m,
        tol * j
    );
}

/// Steiner's theorem J_A = J₀ + m(|d|² I − d dᵀ) and (e, J_A e) about a line.
fn steiner_and_line(input: &mut Input) {
    let p = body_properties(input);
    let point = if input.bool() {
        input.vec3_moderate(5.0)
    } else {
        input.vec3_any()
    };
    let Some(j_a) = call::<mech_mat3_t>("mech_mass_inertia_about", |out| unsafe {
        mech_mass_inertia_about(&p, &v3(point), out)
    }) else {
        return;
    };
    let c = arr(&p.center_of_mass);
    let d = [c[0] - point[0], c[1] - point[1], c[2] - point[2]];
    let d2 = d.iter().map(|x| x * x).sum::<f64>();
    let mut expected = p.inertia_about_com.m;
    for row in 0..3 {
        for col in 0..3 {
            expected[row + 3 * col] += p.mass * (if row == col { d2 } else { 0.0 } - d[row] * d[col]);
        }
    }
    let scale = norm1(&p.inertia_about_com.m) + 3.0 * weighted(weighted(p.mass.abs(), norm1(&d)), norm1(&d));
    assert!(
        close(&j_a.m, &expected, 1e-14 * scale),
        "Steiner: {:?} vs {expected:?}",
        j_a.m
    );
    let direction = if input.bool() {
        input.unit_vec3()
    } else {
        input.vec3_any()
    };
    let Some(moment) = call::<f64>("mech_mass_moment_about_line", |out| unsafe {
        mech_mass_moment_about_line(&p, &v3(point), &v3(direction), out)
    }) else {
        return;
    };
    // Normalised on direction/max|d_i|: the squares of tiny entries would underflow.
    let largest = direction.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let d_hat = direction.map(|x| x / largest);
    let n = d_hat.iter().map(|x| x * x).sum::<f64>().sqrt();
    let e = d_hat.map(|x| x / n);
    let je = mat_vec(&j_a.m, e);
    let want = e[0] * je[0] + e[1] * je[1] + e[2] * je[2];
    // Below the normal range every product and sum rounds to the subnormal spacing 2⁻¹⁰⁷⁴.
    let subnormal = 16.0 * f64::from_bits(1);
    assert!(
        (moment - want).abs() <= 1e-13 * scale + subnormal,
        "moment about a line {moment:e} vs {want:e}; mass {:e}, centre {:?}, J {:?}, point {point:?}, direction {direction:?}",
        p.mass,
        c,
        p.inertia_about_com.m
    );
}

/// J = R diag(I) Rᵀ with R a rotation and I₁ ≤ I₂ ≤ I₃.
fn principal_axes(input: &mut Input) {
    let p = body_properties(input);
    let mut moments = Sentinel::<mech_vec3_t>::new();
    let mut axes = Sentinel::<mech_mat3_t>::new();
    let status = unsafe { mech_mass_principal_axes(&p, moments.ptr(), axes.ptr()) };
    let mut written = doubles_of(&moments.value).to_vec();
    written.extend_from_slice(&axes.value.m);
    check_outputs(
        "mech_mass_principal_axes",
        status,
        moments.untouched() && axes.untouched(),
        &written,
    );
    if status != MECH_STATUS_OK {
        return;
    }
    let i = arr(&moments.value);
    assert!(i[0] <= i[1] && i[1] <= i[2], "moments not ascending: {i:?}");
    let r = axes.value.m;
    let rebuilt = rotate_tensor(&r, &[i[0], 0.0, 0.0, 0.0, i[1], 0.0, 0.0, 0.0, i[2]]);
    let j = p.inertia_about_com.m;
    let sym: Vec<f64> = (0..9).map(|k| 0.5 * j[k] + 0.5 * j[(k % 3) * 3 + k / 3]).collect();
    let scale = norm1(&j);
    // Moments within 1e-10 of the largest are merged into one repeated value (the documented
    // contract): the rebuilt tensor then differs by up to half their gap.
    let largest = i[0].abs().max(i[2].abs());
    let merged = if i[0] == i[1] || i[1] == i[2] {
        1e-10 * largest
    } else {
        0.0
    };
    // A tensor at the subnormal spacing rebuilds to within a few of its steps.
    let subnormal = 16.0 * f64::from_bits(1);
    assert!(
        close(&rebuilt, &sym, 1e-13 * scale + merged + subnormal),
        "R diag(I) Rᵀ = {rebuilt:?}, sym(J) = {sym:?}"
    );
}

/// T = ½ m v² + ½ ωᵀJω, p = m v, D_A = J ω + (c − a) × m v.
fn energy_and_momentum(input: &mut Input) {
    let p = body_properties(input);
    let v = if input.bool() {
        input.vec3_moderate(10.0)
    } else {
        input.vec3_any()
    };
    let w = if input.bool() {
        input.vec3_moderate(10.0)
    } else {
        input.vec3_any()
    };
    let mut energy = Sentinel::<f64>::new();
    let mut momentum = Sentinel::<mech_vec3_t>::new();
    let status = unsafe { mech_mass_kinetic_energy(&p, &v3(v), &v3(w), energy.ptr(), momentum.ptr()) };
    let mut written = vec![energy.value];
    written.extend_from_slice(doubles_of(&momentum.value));
    check_outputs(
        "mech_mass_kinetic_energy",
        status,
        energy.untouched() && momentum.untouched(),
        &written,
    );
    if status == MECH_STATUS_OK {
        let want =
            0.5 * (scaled_quadratic_form(&diagonal(p.mass), v) + scaled_quadratic_form(&p.inertia_about_com.m, w));
        // (m·|v|)·|v|: a square |v|² alone may underflow where the energy does not.
        let scale = 0.5 * weighted(weighted(p.mass, norm1(&v)), norm1(&v))
            + weighted(weighted(norm1(&p.inertia_about_com.m), norm1(&w)), norm1(&w));
        // Below the normal range every product and sum rounds to the subnormal spacing 2⁻¹⁰⁷⁴,
        // an absolute error that no relative tolerance covers.
        let subnormal = 16.0 * f64::from_bits(1);
        assert!(
            (energy.value - want).abs() <= 1e-14 * scale + subnormal,
            "T = {:e} vs {want:e}; mass {:e}, v {v:?}, ω {w:?}, J {:?}",
            energy.value,
            p.mass,
            p.inertia_about_com.m
        );
        assert!(
            close(
                doubles_of(&momentum.value),
                &v.map(|x| p.mass * x),
                1e-15 * weighted(p.mass, norm1(&v)) + subnormal
            ),
            "p = m v: {:?} for mass {:e}, v {v:?}",
            momentum.value,
            p.mass
        );
    }
    let a = input.vec3_moderate(5.0);
    let Some(d) = call::<mech_vec3_t>("mech_mass_angular_momentum", |out| unsafe {
        mech_mass_angular_momentum(&p, &v3(a), &v3(v), &v3(w), out)
    }) else {
        return;
    };
    let c = arr(&p.center_of_mass);
    let r = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let mv = v.map(|x| p.mass * x);
    let jw = mat_vec(&p.inertia_about_com.m, w);
    let cross = [
        r[1] * mv[2] - r[2] * mv[1],
        r[2] * mv[0] - r[0] * mv[2],
        r[0] * mv[1] - r[1] * mv[0],
    ];
    let want = [jw[0] + cross[0], jw[1] + cross[1], jw[2] + cross[2]];
    let scale = weighted(norm1(&p.inertia_about_com.m), norm1(&w)) + weighted(norm1(&r), norm1(&mv));
    assert!(
        close(doubles_of(&d), &want, 1e-14 * scale),
        "D_A = {:?} vs {want:?}",
        arr(&d)
    );
}

/// Primitives: the contract for any arguments, the textbook moments for four shapes.
fn primitive(input: &mut Input) {
    let kind = input.enum_i32(12);
    const COUNTS: [usize; 12] = [0, 1, 2, 1, 1, 3, 3, 2, 2, 2, 2, 1];
    let count = if input.u8() < 240 {
        COUNTS.get(kind as usize).copied().unwrap_or(1)
    } else {
        input.below(5)
    };
    let dims: Vec<f64> = (0..count)
        .map(|_| {
            if input.bool() {
                0.01 + input.fraction()
            } else {
                input.any_f64()
            }
        })
        .collect();
    let amount_kind = input.enum_i32(2);
    let amount = if input.bool() {
        0.1 + input.fraction()
    } else {
        input.any_f64()
    };
    let Some(p) = call::<Props>("mech_mass_primitive", |out| unsafe {
        mech_mass_primitive(kind, dims.as_ptr(), count, amount_kind, amount, out)
    }) else {
        return;
    };
    let j = p.inertia_about_com.m;
    let m = p.mass;
    if amount_kind == MECH_AMOUNT_MASS {
        assert_eq!(m, amount, "a primitive given its mass has another mass");
    }
    // The moments are formed on m/2^e and dims/2^f (e the exponent of m, f of the largest
    // dimension) and scaled back by 2^(e + 2f) at the end, so that neither 0.4·m nor d² leaves
    // the normal range on the way while the moment itself is a normal number.
    let mass_exponent = binary_exponent(m);
    let m = times_power_of_two(m, -mass_exponent);
    let largest = dims.iter().fold(0.0f64, |a, d| a.max(d.abs()));
    let length_exponent = binary_exponent(largest);
    let dims: Vec<f64> = dims.iter().map(|d| times_power_of_two(*d, -length_exponent)).collect();
    let exponent = mass_exponent + 2 * length_exponent;
    let expected = match kind {
        MECH_PRIMITIVE_ROD => Some([m * dims[0] * dims[0] / 12.0, m * dims[0] * dims[0] / 12.0, 0.0]),
        MECH_PRIMITIVE_SPHERE => Some([0.4 * m * dims[0] * dims[0]; 3]),
        MECH_PRIMITIVE_BOX => {
            let [x, y, z] = [dims[0] * dims[0], dims[1] * dims[1], dims[2] * dims[2]];
            Some([m * (y + z) / 12.0, m * (x + z) / 12.0, m * (x + y) / 12.0])
        }
        MECH_PRIMITIVE_CYLINDER => {
            let (r2, h2) = (dims[0] * dims[0], dims[1] * dims[1]);
            Some([m * (3.0 * r2 + h2) / 12.0, m * (3.0 * r2 + h2) / 12.0, 0.5 * m * r2])
        }
        _ => None,
    };
    if let Some(want) = expected {
        let want = want.map(|x| times_power_of_two(x, exponent));
        let diag = [j[0], j[4], j[8]];
        // A moment below the normal range is known only to the subnormal spacing 2⁻¹⁰⁷⁴.
        let scale = norm1(&want) + 16.0 * f64::from_bits(1);
        assert!(
            close(&diag, &want, 1e-14 * scale),
            "primitive {kind}: {diag:?} vs {want:?}; mass {m:e}·2^{mass_exponent}, dims {dims:?}·2^{length_exponent}"
        );
        assert!(
            close(&[j[1], j[2], j[3], j[5], j[6], j[7]], &[0.0; 6], 1e-14 * scale),
            "off-diagonal"
        );
    }
}

/// Anything repaired passes the check with no issue.
fn check_and_repair(input: &mut Input) {
    let p = body_properties(input);
    let tolerance = if input.bool() { 0.0 } else { input.any_f64() };
    let mut validity = Sentinel::<mech_mass_validity_t>::new();
    let status = unsafe { mech_mass_check(&p, tolerance, validity.ptr()) };
    check_outputs(
        "mech_mass_check",
        status,
        validity.untouched(),
        doubles_of(&validity.value.moments),
    );
    let mut change = Sentinel::<f64>::new();
    let mut repaired = Sentinel::<Props>::new();
    let status = unsafe { mech_mass_repair(&p, tolerance, repaired.ptr(), change.ptr()) };
    let mut written = doubles_of(&repaired.value).to_vec();
    written.push(change.value);
    check_outputs(
        "mech_mass_repair",
        status,
        repaired.untouched() && change.untouched(),
        &written,
    );
    if status != MECH_STATUS_OK {
        return;
    }
    // Checked at the default tolerance: the rebuilt tensor carries rounding, which a tolerance
    // below it (any positive number is accepted) would flag.
    let mut again = Sentinel::<mech_mass_validity_t>::new();
    let status = unsafe { mech_mass_check(&repaired.value, tolerance.max(1e-9), again.ptr()) };
    check_status("mech_mass_check", status);
    if status == MECH_STATUS_OK && repaired.value.mass > 0.0 {
        assert_eq!(
            again.value.issues,
            0,
            "a repaired body still has issues {:#x}: moments {:?}, repaired J {:?} from J {:?}, tolerance {tolerance}",
            again.value.issues,
            doubles_of(&again.value.moments),
            repaired.value.inertia_about_com.m,
            p.inertia_about_com.m
        );
    }
}

/// A small mesh (a perturbed octahedron or arbitrary triangles) and the same mesh moved
/// rigidly: the second call, reusing the first report's topology, gives the moved properties.
fn mesh(input: &mut Input) {
    const OCTAHEDRON: [[u32; 3]; 8] = [
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    let base = [
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let wild = input.u8() >= 200;
    let vertices: Vec<f64> = base
        .iter()
        .flat_map(|v| v.map(|c| c * 0.5))
        .map(|c| if wild { input.any_f64() } else { c + input.moderate(0.2) })
        .collect();
    let mut indices: Vec<u32> = OCTAHEDRON.iter().flatten().copied().collect();
    if input.u8() >= 224 {
        let k = input.below(indices.len());
        indices[k] = u32::from(input.u8()) % 8;
    }
    let amount_kind = input.enum_i32(2);
    let amount = if input.bool() { 1.0 } else { input.any_f64() };
    let options = mech_mesh_options_t {
        model: input.enum_i32(2),
        open_mesh: input.enum_i32(2),
        inside_out: input.enum_i32(2),
        degenerate: input.enum_i32(2),
    };
    let mut report = Sentinel::<mech_mesh_report_t>::new();
    let Some(first) = call::<Props>("mech_mass_mesh", |out| unsafe {
        mech_mass_mesh(
            vertices.as_ptr(),
            6,
            indices.as_ptr(),
            8,
            amount_kind,
            amount,
            &options,
            out,
            report.ptr(),
        )
    }) else {
        assert!(report.untouched(), "the report was written by a failed call");
        return;
    };
    let q = input.unit_quaternion();
    let r = rotation_of(q);
    let t = input.vec3_moderate(100.0);
    let moved: Vec<f64> = vertices
        .chunks_exact(3)
        .flat_map(|v| {
            let x = mat_vec(&r, [v[0], v[1], v[2]]);
            [x[0] + t[0], x[1] + t[1], x[2] + t[2]]
        })
        .collect();
    let earlier = report.value;
    let Some(second) = call::<Props>("mech_mass_mesh_same_connectivity", |out| unsafe {
        mech_mass_mesh_same_connectivity(
            moved.as_ptr(),
            6,
            indices.as_ptr(),
            8,
            amount_kind,
            amount,
            &options,
            &earlier,
            out,
            std::ptr::null_mut(),
        )
    }) else {
        return;
    };
    let bound = earlier.relative_error_bound;
    let reach: f64 = vertices.iter().map(|c| c.abs()).fold(0.0, f64::max) + norm1(&t);
    // Moving the vertices rounds each by ~ε·reach, which changes the volume by up to that times
    // the total area (a sliver's area is large against its volume).
    let corner = |k: u32| {
        let k = k as usize;
        [vertices[3 * k], vertices[3 * k + 1], vertices[3 * k + 2]]
    };
    let (mut area, mut perimeter) = (0.0, 0.0);
    for t in indices.chunks_exact(3) {
        let (a, b, c) = (corner(t[0] % 6), corner(t[1] % 6), corner(t[2] % 6));
        let (u, v) = (
            [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
            [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
        );
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        area += 0.5 * norm1(&n);
        perimeter += norm1(&u) + norm1(&v) + norm1(&[c[0] - b[0], c[1] - b[1], c[2] - b[2]]);
    }
    // A solid's volume moves by displacement × area, a shell's area by displacement × perimeter;
    // the displacement is the rounding of R v + t, some tens of ulps of `reach` per coordinate
    // (R itself is rounded): 1024 ulps bound it with room for the constants.
    let lever = if earlier.model == MECH_MESH_SOLID {
        area
    } else {
        perimeter
    };
    let rho = 64.0 * bound + 1024.0 * f64::EPSILON * reach * lever / earlier.measure.abs().max(1e-300);
    if !(rho < 1e-3) {
        return;
    }
    assert!(
        (second.mass - first.mass).abs() <= rho * first.mass,
        "mass {} moved becomes {} (rho {rho:e}, bound {bound:e}, reach {reach:e}, lever {lever:e}, measure {:e}, model {}, vertices {vertices:?})",
        first.mass,
        second.mass,
        earlier.measure,
        earlier.model
    );
    let want_c = mat_vec(&r, arr(&first.center_of_mass));
    for k in 0..3 {
        assert!(
            (arr(&second.center_of_mass)[k] - want_c[k] - t[k]).abs() <= rho * reach,
            "moved mesh centre"
        );
    }
    let want_j = rotate_tensor(&r, &first.inertia_about_com.m);
    let scale = norm1(&first.inertia_about_com.m) + first.mass * reach * reach;
    // A body of subnormal mass has subnormal moments, each a sum of some hundred products
    // rounded to the absolute spacing 2⁻¹⁰⁷⁴.
    let subnormal = 1024.0 * f64::from_bits(1);
    assert!(
        close(&second.inertia_about_com.m, &want_j, rho * scale + subnormal),
        "moved mesh tensor: {:?} vs {want_j:?} (rho {rho:e}, scale {scale:e}, mass {}, reach {reach:e}, measure {:e}, model {}, vertices {vertices:?}, t {t:?})",
        second.inertia_about_com.m,
        first.mass,
        earlier.measure,
        earlier.model
    );
}

/// On a tree: T from mech_tree_kinetic_energy equals ½ q̇ᵀ A q̇ with A from mech_tree_mass_matrix,
/// and the momenta are A q̇.
fn tree_quantities(input: &mut Input) {
    let Some(tree) = build_tree(input) else { return };
    let bodies: Vec<Props> = (0..tree.bodies).map(|_| body_properties(input)).collect();
    let q_dot: Vec<f64> = (0..tree.dof).map(|_| input.moderate(3.0)).collect();
    let q: Vec<f64> = (0..tree.dof).map(|_| input.moderate(3.0)).collect();
    let status = unsafe { mech_tree_set_state(tree.handle, q.as_ptr(), q_dot.as_ptr(), tree.dof) };
    check_status("mech_tree_set_state", status);
    let n = tree.dof;
    let mut a = sentinel_doubles(n * n);
    let status = unsafe { mech_tree_mass_matrix(tree.handle, bodies.as_ptr(), bodies.len(), a.as_mut_ptr(), n) };
    check_outputs("mech_tree_mass_matrix", status, doubles_untouched(&a), &a);
    let mut energy = Sentinel::<f64>::new();
    let mut momenta = sentinel_doubles(n);
    let kinetic = unsafe {
        mech_tree_kinetic_energy(
            tree.handle,
            bodies.as_ptr(),
            bodies.len(),
            energy.ptr(),
            momenta.as_mut_ptr(),
            n,
        )
    };
    check_outputs(
        "mech_tree_kinetic_energy",
        kinetic,
        energy.untouched() && doubles_untouched(&momenta),
        &momenta,
    );
    let mut system = Sentinel::<Props>::new();
    let mut jacobian = sentinel_doubles(3 * n);
    let com = unsafe {
        mech_tree_center_of_mass(
            tree.handle,
            bodies.as_ptr(),
            bodies.len(),
            system.ptr(),
            jacobian.as_mut_ptr(),
            n,
        )
    };
    check_outputs(
        "mech_tree_center_of_mass",
        com,
        system.untouched() && doubles_untouched(&jacobian),
        &jacobian,
    );
    let (w0, v0) = (v3(input.vec3_moderate(2.0)), v3(input.vec3_moderate(2.0)));
    let mut split = Sentinel::<mech_energy_split_t>::new();
    let (mut b, mut p) = (sentinel_doubles(n), sentinel_doubles(n));
    let status = unsafe {
        mech_tree_energy_split(
            tree.handle,
            bodies.as_ptr(),
            bodies.len(),
            &w0,
            &v0,
            split.ptr(),
            b.as_mut_ptr(),
            p.as_mut_ptr(),
            n,
        )
    };
    check_outputs(
        "mech_tree_energy_split",
        status,
        split.untouched() && doubles_untouched(&b),
        &b,
    );
    if status != MECH_STATUS_OK || kinetic != MECH_STATUS_OK {
        return;
    }
    trace!(
        "tree quantities: bodies {bodies:?}, q {q:?}, q̇ {q_dot:?}, A {a:?}, T {}",
        energy.value
    );
    // In units of 2^e ≈ the largest term |a_ij q̇_i q̇_j|: entries near f64::MAX overflow the
    // plain sums, and terms far below the largest (an entry of 1e301 on a coordinate at rest
    // beside entries of 1e-2) must not be scaled away; subnormal results round to the absolute
    // spacing 2⁻¹⁰⁷⁴, which `slack` allows for.
    let e = (0..n * n)
        .filter(|&k| a[k] != 0.0 && q_dot[k % n] != 0.0 && q_dot[k / n] != 0.0)
        .map(|k| binary_exponent(a[k]) + binary_exponent(q_dot[k % n]) + binary_exponent(q_dot[k / n]))
        .max()
        .unwrap_or(0);
    let down = |x: f64| times_power_of_two(x, -e);
    let terms: Vec<f64> = (0..n * n)
        .map(|k| {
            let (qi, qj) = (q_dot[k % n], q_dot[k / n]);
            // A term with a coordinate at rest is exactly zero, whatever its entry.
            if qi == 0.0 || qj == 0.0 {
                0.0
            } else {
                down(a[k]) * qi * qj
            }
        })
        .collect();
    let slack = down(16.0 * f64::from_bits(1));
    let t = 0.5 * terms.iter().sum::<f64>();
    let scale: f64 = terms.iter().map(|x| x.abs()).sum();
    assert!(
        (down(energy.value) - t).abs() <= 1e-12 * scale + slack,
        "T = {:e} but ½ q̇ᵀAq̇ = {t:e}·2^{e}",
        energy.value
    );
    // Each momentum in units of its own largest term |a_ij q̇_j|, as T above.
    for i in 0..n {
        let moving = |j: &usize| q_dot[*j] != 0.0 && a[i + n * j] != 0.0;
        let row_exponent = (0..n)
            .filter(moving)
            .map(|j| binary_exponent(a[i + n * j]) + binary_exponent(q_dot[j]))
            .max()
            .unwrap_or(0);
        let row_terms: Vec<f64> = (0..n)
            .filter(moving)
            .map(|j| times_power_of_two(a[i + n * j], -row_exponent) * q_dot[j])
            .collect();
        let want: f64 = row_terms.iter().sum();
        let row_scale: f64 = row_terms.iter().map(|x| x.abs()).sum();
        let row_slack = times_power_of_two(16.0 * f64::from_bits(1), -row_exponent);
        assert!(
            (times_power_of_two(momenta[i], -row_exponent) - want).abs() <= 1e-12 * row_scale + row_slack,
            "momentum {i}: {:e} ≠ (A q̇) = {want:e}·2^{row_exponent}",
            momenta[i]
        );
    }
    assert!(
        (down(split.value.t2) - t).abs() <= 1e-12 * scale + slack,
        "T₂ of the split ≠ ½ q̇ᵀAq̇"
    );
}

fuzz_target!(|data: &[u8]| {
    let mut input = Input::new(data);
    let mut steps = 0;
    while !input.is_empty() && steps < 32 {
        steps += 1;
        match input.u8() % 9 {
            0 => transform_round_trip(&mut input),
            1 => combine_subtract(&mut input),
            2 => steiner_and_line(&mut input),
            3 => principal_axes(&mut input),
            4 => energy_and_momentum(&mut input),
            5 => primitive(&mut input),
            6 => check_and_repair(&mut input),
            7 => mesh(&mut input),
            _ => tree_quantities(&mut input),
        }
    }
});
