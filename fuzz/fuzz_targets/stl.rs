//! STL, binary and ASCII (the reader tells them apart by content): parsing never panics, and a
//! mesh that parses has mass properties invariant under a rigid motion (see `mesh_oracle`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use mechanica::mass::io::read_stl;
use mechanica_fuzz::{Input, mesh_oracle};

fuzz_target!(|data: &[u8]| {
    if let Ok(mesh) = read_stl(&mut std::io::Cursor::new(data)) {
        // The motion comes from the file's last bytes, so mutations near the end explore it.
        let tail = &data[data.len().saturating_sub(16)..];
        mesh_oracle::check_rigid_motion_invariance(&mesh, &mut Input::new(tail));
    }
});
