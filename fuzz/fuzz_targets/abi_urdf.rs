//! URDF through the C ABI: any bytes given to mech_tree_from_urdf_string and
//! mech_mechanism_from_urdf_string (meshes looked for in an empty private directory, with
//! both option sets). Besides the status contract (`oracle`): a failed call leaves its output
//! untouched; a tree and a mechanism read from the same text agree on the number of
//! coordinates; every link and coordinate has a name whose reported length is the copied one.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mechanica::ffi::*;
use mechanica_fuzz::oracle::check_status;
use std::ffi::c_char;

/// Reads one name through `query` (a length query, then a copy), checking the length protocol.
fn name_of(query: impl Fn(*mut c_char, usize, *mut usize) -> mech_status_t, what: &str) -> usize {
    let mut length = usize::MAX;
    let status = query(std::ptr::null_mut(), 0, &mut length);
    check_status(what, status);
    assert_eq!(status, MECH_STATUS_OK, "{what}: length query failed");
    let mut buffer = vec![0x5a as c_char; length + 1];
    let mut copied = 0;
    let status = query(buffer.as_mut_ptr(), buffer.len(), &mut copied);
    assert_eq!(status, MECH_STATUS_OK, "{what}: copy failed");
    assert_eq!(copied, length, "{what}: the lengths differ");
    assert_eq!(buffer[length], 0, "{what}: no terminating NUL");
    length
}

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("mechanica-fuzz-abi-urdf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch directory");
    let mesh_dir = std::ffi::CString::new(dir.to_string_lossy().as_bytes()).expect("no NUL in the path");
    for options in [
        mech_urdf_options_t {
            repair_inertia: 0,
            allow_missing_mesh: 0,
        },
        mech_urdf_options_t {
            repair_inertia: 1,
            allow_missing_mesh: 1,
        },
    ] {
        let text = data.as_ptr().cast::<c_char>();
        let sentinel = 0x10 as *mut mech_tree_t;
        let mut tree = sentinel;
        // SAFETY: `data` holds `data.len()` bytes; the other pointers are live locals.
        let status = unsafe { mech_tree_from_urdf_string(text, data.len(), mesh_dir.as_ptr(), &options, &mut tree) };
        check_status("mech_tree_from_urdf_string", status);
        let sentinel_m = 0x10 as *mut mech_mechanism_t;
        let mut mechanism = sentinel_m;
        // SAFETY: as above.
        let status_m =
            unsafe { mech_mechanism_from_urdf_string(text, data.len(), mesh_dir.as_ptr(), &options, &mut mechanism) };
        check_status("mech_mechanism_from_urdf_string", status_m);
        if status != MECH_STATUS_OK {
            assert_eq!(tree, sentinel, "a failed read wrote its output");
        }
        if status_m != MECH_STATUS_OK {
            assert_eq!(mechanism, sentinel_m, "a failed read wrote its output");
        }
        if status == MECH_STATUS_OK {
            let (mut bodies, mut dof) = (0, 0);
            // SAFETY: `tree` is live.
            assert_eq!(unsafe { mech_tree_size(tree, &mut bodies, &mut dof) }, MECH_STATUS_OK);
            for b in 0..bodies {
                // SAFETY: `tree` is live; the buffers are sized by name_of.
                name_of(
                    |p, c, l| unsafe { mech_tree_link_name(tree, b, p, c, l) },
                    "mech_tree_link_name",
                );
            }
            for k in 0..dof {
                // SAFETY: as above.
                name_of(
                    |p, c, l| unsafe { mech_tree_coordinate_name(tree, k, p, c, l) },
                    "mech_tree_coordinate_name",
                );
            }
            if status_m == MECH_STATUS_OK {
                let mut n = 0;
                // SAFETY: `mechanism` is live.
                assert_eq!(unsafe { mech_mechanism_dof(mechanism, &mut n) }, MECH_STATUS_OK);
                assert_eq!(n, dof, "tree and mechanism disagree on the coordinates");
            }
            // SAFETY: `tree` is live and not used afterwards.
            unsafe { mech_tree_destroy(tree) };
        }
        if status_m == MECH_STATUS_OK {
            // SAFETY: `mechanism` is live and not used afterwards.
            unsafe { mech_mechanism_destroy(mechanism) };
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
});
