// Reads the Franka Panda arm from URDF through the C++ header, seeks the minimum of its
// potential under gravity within the joint limits, and prints the modes about it. Coordinates
// that end on a joint limit are held there by the limit, not by gravity: the modes about such
// a configuration can include unstable directions along them.
//
//   panda_modes [path/to/panda.urdf]
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "mechanica.hpp"

int main(int argc, char **argv) {
    const std::string path = argc > 1 ? argv[1] : "panda.urdf";
    try {
        auto panda = mechanica::mechanism::from_urdf(path);
        const std::size_t n = panda.dof();
        std::printf("%s: %zu coordinates\n", path.c_str(), n);
        // Start inside every joint's limits (joint 4 and 6 exclude 0; the fingers half open).
        std::vector<double> q0{0.0, 0.3, 0.0, -1.5, 0.0, 1.8, 0.8, 0.02, 0.02};
        q0.resize(n, 0.0);
        const mechanica::matrix q = panda.equilibrium(q0, MECH_SEEK_MINIMUM);
        std::printf("equilibrium:\n");
        for (std::size_t k = 0; k < n; ++k) std::printf("  %-22s % .6f\n", panda.coordinate_name(k).c_str(), q[k]);
        const mechanica::mechanism_modes modes = panda.modes({q.data(), q.rows()});
        std::printf("modes (omega^2 in rad^2/s^2, with error bounds):\n");
        for (std::size_t k = 0; k < modes.omega_sq.rows(); ++k)
            std::printf("  %zu  % .9e  +- %.1e\n", k, modes.omega_sq[k], modes.error_bounds[k]);
        std::printf("unstable directions: %zu, zero modes: %zu\n", modes.stability.unstable_directions,
                    modes.stability.zero_modes);
    } catch (const mechanica::error &e) {
        std::fprintf(stderr, "panda_modes: %s\n", e.what());
        return 1;
    } catch (const std::exception &e) {
        std::fprintf(stderr, "panda_modes: %s\n", e.what());
        return 1;
    }
    return 0;
}
