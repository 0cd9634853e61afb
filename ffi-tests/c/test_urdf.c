/* URDF through the C ABI: a double pendulum of point masses read from a string and from a file
 * (names, tree size, modes against the closed form ω² = (2 ∓ √2) g/L), broken robots whose
 * errors name the link or joint and the field, and a massless finger left out of the modes. */
#include "check.h"

#include <unistd.h>

static const double G = 9.81, L = 0.5;

/* Two point masses of 1 kg, each L below its joint, on revolute joints about y. */
static const char PENDULUM[] =
    "<robot name=\"pendulum\">"
    "<link name=\"base\"/>"
    "<link name=\"upper\"><inertial><origin xyz=\"0 0 -0.5\"/><mass value=\"1\"/>"
    "<inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"/></inertial></link>"
    "<link name=\"lower\"><inertial><origin xyz=\"0 0 -0.5\"/><mass value=\"1\"/>"
    "<inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"/></inertial></link>"
    "<joint name=\"shoulder\" type=\"continuous\"><parent link=\"base\"/><child link=\"upper\"/>"
    "<axis xyz=\"0 1 0\"/></joint>"
    "<joint name=\"elbow\" type=\"revolute\"><parent link=\"upper\"/><child link=\"lower\"/>"
    "<origin xyz=\"0 0 -0.5\"/><axis xyz=\"0 1 0\"/><limit lower=\"-2\" upper=\"2\" effort=\"1\" velocity=\"1\"/>"
    "</joint></robot>";

/* Replaces the first occurrence of `from` in PENDULUM by `to` (into `out`, `capacity` bytes). */
static void variant(const char *from, const char *to, char *out, size_t capacity) {
    const char *at = strstr(PENDULUM, from);
    CHECK(at != NULL);
    size_t head = (size_t)(at - PENDULUM);
    int written = snprintf(out, capacity, "%.*s%s%s", (int)head, PENDULUM, to, at + strlen(from));
    CHECK(written > 0 && (size_t)written < capacity);
}

static void last_error_contains(const char *a, const char *b) {
    char message[1024];
    mech_last_error(message, sizeof message);
    if (!strstr(message, a) || !strstr(message, b)) fprintf(stderr, "last error: %s\n", message);
    CHECK(strstr(message, a) != NULL && strstr(message, b) != NULL);
}

static void names_of_the_tree(mech_tree_t *tree) {
    size_t bodies = 0, dof = 0, length = 0;
    CHECK_STATUS(mech_tree_size(tree, &bodies, &dof), MECH_STATUS_OK);
    CHECK(bodies == 3 && dof == 2);
    const char *links[] = {"base", "upper", "lower"}, *joints[] = {"", "shoulder", "elbow"};
    char name[32];
    for (size_t b = 0; b < 3; ++b) {
        CHECK_STATUS(mech_tree_link_name(tree, b, name, sizeof name, &length), MECH_STATUS_OK);
        CHECK(strcmp(name, links[b]) == 0 && length == strlen(links[b]));
        CHECK_STATUS(mech_tree_joint_name(tree, b, name, sizeof name, &length), MECH_STATUS_OK);
        CHECK(strcmp(name, joints[b]) == 0 && length == strlen(joints[b]));
    }
    CHECK_STATUS(mech_tree_coordinate_name(tree, 1, name, sizeof name, &length), MECH_STATUS_OK);
    CHECK(strcmp(name, "elbow") == 0);
    /* A length query, then a buffer one byte short: nothing is written. */
    CHECK_STATUS(mech_tree_coordinate_name(tree, 0, NULL, 0, &length), MECH_STATUS_OK);
    CHECK(length == strlen("shoulder"));
    FILL_SENTINEL(name, sizeof name);
    size_t untouched = 77;
    CHECK_STATUS(mech_tree_coordinate_name(tree, 0, name, length, &untouched), MECH_STATUS_BUFFER_TOO_SMALL);
    CHECK(mech_untouched(name, sizeof name) && untouched == 77);
    CHECK_STATUS(mech_tree_link_name(tree, 3, name, sizeof name, &length), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_tree_coordinate_name(tree, 2, name, sizeof name, &length), MECH_STATUS_INVALID_ARGUMENT);
}

static void modes_match_the_closed_form(mech_mechanism_t *m) {
    size_t dof = 0, length = 0, found = 0;
    CHECK_STATUS(mech_mechanism_dof(m, &dof), MECH_STATUS_OK);
    CHECK(dof == 2);
    char name[32];
    CHECK_STATUS(mech_mechanism_link_name(m, 2, name, sizeof name, &length), MECH_STATUS_OK);
    CHECK(strcmp(name, "lower") == 0);
    CHECK_STATUS(mech_mechanism_coordinate_name(m, 0, name, sizeof name, &length), MECH_STATUS_OK);
    CHECK(strcmp(name, "shoulder") == 0);
    const double q[2] = {0.0, 0.0};
    double w2[2], bounds[2];
    mech_modal_kind_t kinds[2];
    mech_stability_t stability;
    CHECK_STATUS(mech_mechanism_modes(m, q, 2, 0, w2, bounds, kinds, NULL, &found, &stability), MECH_STATUS_OK);
    CHECK(found == 2 && stability.unstable_directions == 0);
    CHECK_NEAR(w2[0], (2.0 - sqrt(2.0)) * G / L, 1e-12);
    CHECK_NEAR(w2[1], (2.0 + sqrt(2.0)) * G / L, 1e-12);
}

static void from_string_and_file(void) {
    mech_urdf_options_t options;
    CHECK_STATUS(mech_urdf_options_default(&options), MECH_STATUS_OK);
    CHECK(options.repair_inertia == 0 && options.allow_missing_mesh == 0);
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_from_urdf_string(PENDULUM, strlen(PENDULUM), NULL, &options, &tree), MECH_STATUS_OK);
    names_of_the_tree(tree);
    /* A mechanism made from the URDF tree keeps its names (mech_mechanism_create wants a
     * positive mass for every body: the fixed base gets one at its origin). */
    const mech_mass_properties_t point = {1.0, {0.0, 0.0, -L}, {{0}}};
    const mech_mass_properties_t masses[3] = {{1.0, {0, 0, 0}, {{0}}}, point, point};
    mech_mechanism_t *copy = NULL;
    CHECK_STATUS(mech_mechanism_create(tree, masses, 3, &copy), MECH_STATUS_OK);
    size_t length = 0;
    CHECK_STATUS(mech_mechanism_link_name(copy, 1, NULL, 0, &length), MECH_STATUS_OK);
    CHECK(length == strlen("upper"));
    mech_mechanism_destroy(copy);
    mech_tree_destroy(tree);

    mech_mechanism_t *m = NULL;
    CHECK_STATUS(mech_mechanism_from_urdf_string(PENDULUM, strlen(PENDULUM), ".", NULL, &m), MECH_STATUS_OK);
    modes_match_the_closed_form(m);
    mech_mechanism_destroy(m);

    char path[64];
    snprintf(path, sizeof path, "/tmp/mech_test_urdf_%ld.urdf", (long)getpid());
    FILE *file = fopen(path, "w");
    CHECK(file != NULL);
    fputs(PENDULUM, file);
    fclose(file);
    CHECK_STATUS(mech_tree_from_urdf(path, NULL, &tree), MECH_STATUS_OK);
    names_of_the_tree(tree);
    mech_tree_destroy(tree);
    CHECK_STATUS(mech_mechanism_from_urdf(path, &options, &m), MECH_STATUS_OK);
    modes_match_the_closed_form(m);
    mech_mechanism_destroy(m);
    remove(path);
    CHECK_STATUS(mech_tree_from_urdf(path, NULL, &tree), MECH_STATUS_IO_ERROR);
}

/* Each broken robot: its status, and two words its message must contain. */
static void broken(const char *from, const char *to, mech_status_t status, const char *a, const char *b) {
    char text[sizeof PENDULUM + 256];
    variant(from, to, text, sizeof text);
    mech_mechanism_t *sentinel = (mech_mechanism_t *)&sentinel;
    CHECK_STATUS(mech_mechanism_from_urdf_string(text, strlen(text), NULL, NULL, &sentinel), status);
    CHECK(sentinel == (mech_mechanism_t *)&sentinel);
    last_error_contains(a, b);
}

static void broken_robots(void) {
    broken("<robot", "<robot><", MECH_STATUS_PARSE_ERROR, "URDF text", "");
    broken("ixx=\"0\"", "ixx=\"5\"", MECH_STATUS_INVALID_ARGUMENT, "link \"upper\"", "triangle");
    broken("mass value=\"1\"", "mass value=\"-1\"", MECH_STATUS_INVALID_ARGUMENT, "link \"upper\"", "mass");
    broken("<parent link=\"upper\"/>", "<parent link=\"nowhere\"/>", MECH_STATUS_INVALID_ARGUMENT, "joint \"elbow\"",
           "parent link \"nowhere\"");
    broken("<axis xyz=\"0 1 0\"/></joint>", "<axis xyz=\"0 0 0\"/></joint>", MECH_STATUS_INVALID_ARGUMENT,
           "joint \"shoulder\"", "axis");
    broken("<origin xyz=\"0 0 -0.5\"/><axis", "<origin xyz=\"0 0 nan\"/><axis", MECH_STATUS_NON_FINITE,
           "joint \"elbow\"", "origin");
    broken("<link name=\"base\"/>",
           "<link name=\"base\"><collision><geometry><mesh filename=\"package://robot/base.stl\"/></geometry>"
           "</collision></link>",
           MECH_STATUS_IO_ERROR, "link \"base\"", "mesh \"package://robot/base.stl\"");
    /* With allow_missing_mesh the link is massless instead. */
    char text[sizeof PENDULUM + 256];
    variant("<link name=\"base\"/>",
            "<link name=\"base\"><visual><geometry><mesh filename=\"gone.dae\"/></geometry></visual></link>", text,
            sizeof text);
    mech_urdf_options_t lenient = {0, 1};
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_from_urdf_string(text, strlen(text), NULL, &lenient, &tree), MECH_STATUS_OK);
    mech_tree_destroy(tree);
    lenient.allow_missing_mesh = 2;
    CHECK_STATUS(mech_tree_from_urdf_string(text, strlen(text), NULL, &lenient, &tree), MECH_STATUS_INVALID_ARGUMENT);
    /* Sizes and pointers. */
    CHECK_STATUS(mech_tree_from_urdf_string(PENDULUM, (size_t)MECH_URDF_MAX_BYTES + 1, NULL, NULL, &tree),
                 MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_tree_from_urdf_string(NULL, 10, NULL, NULL, &tree), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_from_urdf(NULL, NULL, &tree), MECH_STATUS_NULL_POINTER);
    const char not_utf8[] = "<robot name=\"\xff\"/>";
    CHECK_STATUS(mech_tree_from_urdf_string(not_utf8, strlen(not_utf8), NULL, NULL, &tree), MECH_STATUS_PARSE_ERROR);
    /* A tree built body by body has no names. */
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    size_t length = 0;
    CHECK_STATUS(mech_tree_link_name(tree, 0, NULL, 0, &length), MECH_STATUS_INVALID_ARGUMENT);
    mech_tree_destroy(tree);
}

/* A massless finger without a spring at the lower link's tip (its rows of A and B are zero),
 * and a material with a bare <texture/> as some exporters write: the finger is left out of the
 * modes, which are the pendulum's two with a zero finger row in the shapes. */
static void a_massless_finger_is_left_out_of_the_modes(void) {
    char text[2048];
    variant("</robot>",
            "<link name=\"finger\"><visual><geometry><box size=\"0.01 0.01 0.01\"/></geometry>"
            "<material name=\"grey\"><texture/></material></visual></link>"
            "<joint name=\"finger_joint\" type=\"revolute\"><parent link=\"lower\"/><child link=\"finger\"/>"
            "<origin xyz=\"0 0 -0.5\"/><axis xyz=\"1 0 0\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" "
            "velocity=\"1\"/></joint></robot>",
            text, sizeof text);
    mech_mechanism_t *m = NULL;
    CHECK_STATUS(mech_mechanism_from_urdf_string(text, strlen(text), ".", NULL, &m), MECH_STATUS_OK);
    const double q[3] = {0.0, 0.0, 0.0};
    double w2[3], bounds[3], shapes[9];
    mech_modal_kind_t kinds[3];
    mech_stability_t stability;
    size_t found = 0;
    CHECK_STATUS(mech_mechanism_modes(m, q, 3, 0, w2, bounds, kinds, shapes, &found, &stability), MECH_STATUS_OK);
    CHECK(found == 2 && stability.unstable_directions == 0);
    CHECK_NEAR(w2[0], (2.0 - sqrt(2.0)) * G / L, 1e-12);
    CHECK_NEAR(w2[1], (2.0 + sqrt(2.0)) * G / L, 1e-12);
    CHECK(kinds[2] == MECH_MODAL_KIND_INFINITE && w2[2] == 0.0 && bounds[2] == 0.0);
    CHECK(shapes[2] == 0.0 && shapes[5] == 0.0);
    CHECK(shapes[6] == 0.0 && shapes[7] == 0.0 && shapes[8] == 0.0);
    mech_mechanism_destroy(m);
}

int main(void) {
    from_string_and_file();
    broken_robots();
    a_massless_finger_is_left_out_of_the_modes();
    return CHECK_DONE();
}
