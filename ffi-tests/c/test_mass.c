/* The mass-properties C ABI: primitives, Steiner, composition, holes, transformation, principal
 * axes, validity and repair, momenta and energy, and triangle meshes, with their error paths.
 * Reference values are textbook closed forms. */
#include "check.h"

#include <stdint.h>

static const double EPS = 2.220446049250313e-16;

static double entry(const mech_mat3_t *m, int row, int col) { return m->m[row + 3 * col]; }

static mech_mass_properties_t make_box(double m, double a, double b, double c, double x, double y, double z) {
    mech_mass_properties_t p;
    memset(&p, 0, sizeof p);
    p.mass = m;
    p.center_of_mass.x = x;
    p.center_of_mass.y = y;
    p.center_of_mass.z = z;
    p.inertia_about_com.m[0] = m * (b * b + c * c) / 12.0;
    p.inertia_about_com.m[4] = m * (a * a + c * c) / 12.0;
    p.inertia_about_com.m[8] = m * (a * a + b * b) / 12.0;
    return p;
}

static void point_and_steiner(void) {
    mech_vec3_t pos = {3.0, 0.0, 0.0};
    mech_mass_properties_t p;
    CHECK_STATUS(mech_mass_point(2.0, &pos, &p), MECH_STATUS_OK);
    mech_vec3_t origin = {0.0, 0.0, 0.0};
    mech_mat3_t j;
    CHECK_STATUS(mech_mass_inertia_about(&p, &origin, &j), MECH_STATUS_OK);
    CHECK_NEAR(entry(&j, 0, 0), 0.0, 0.0);
    CHECK_NEAR(entry(&j, 1, 1), 18.0, 0.0);
    CHECK_NEAR(entry(&j, 2, 2), 18.0, 0.0);

    mech_mass_properties_t sentinel;
    FILL_SENTINEL(&sentinel, sizeof sentinel);
    CHECK_STATUS(mech_mass_point(-1.0, &pos, &sentinel), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_mass_point(NAN, &pos, &sentinel), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_mass_point(1.0, NULL, &sentinel), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&sentinel, sizeof sentinel));
    CHECK_STATUS(mech_mass_point(1.0, &pos, NULL), MECH_STATUS_NULL_POINTER);

    mech_mat3_t js;
    FILL_SENTINEL(&js, sizeof js);
    mech_vec3_t bad = {INFINITY, 0.0, 0.0};
    CHECK_STATUS(mech_mass_inertia_about(&p, &bad, &js), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_mass_inertia_about(NULL, &origin, &js), MECH_STATUS_NULL_POINTER);
    mech_mass_properties_t neg = p;
    neg.mass = -2.0;
    CHECK_STATUS(mech_mass_inertia_about(&neg, &origin, &js), MECH_STATUS_INVALID_ARGUMENT);
    CHECK(mech_untouched(&js, sizeof js));
    CHECK_STATUS(mech_mass_inertia_about(&p, &origin, NULL), MECH_STATUS_NULL_POINTER);
}

static void primitives(void) {
    mech_mass_properties_t p;
    double r = 0.5;
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_SPHERE, &r, 1, MECH_AMOUNT_MASS, 3.0, &p), MECH_STATUS_OK);
    CHECK_NEAR(p.mass, 3.0, 0.0);
    CHECK_NEAR(entry(&p.inertia_about_com, 0, 0), 0.4 * 3.0 * 0.25, 4 * EPS);

    double cyl[2] = {0.5, 2.0};
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_CYLINDER, cyl, 2, MECH_AMOUNT_DENSITY, 1000.0, &p),
                 MECH_STATUS_OK);
    double m = 1000.0 * 3.14159265358979323846 * 0.25 * 2.0;
    CHECK_NEAR(p.mass, m, 1e-12 * m);
    CHECK_NEAR(entry(&p.inertia_about_com, 0, 0), m * (3 * 0.25 + 4.0) / 12.0, 1e-12 * m);
    CHECK_NEAR(entry(&p.inertia_about_com, 2, 2), m * 0.25 / 2.0, 1e-12 * m);

    double cone[2] = {1.0, 4.0};
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_CONE, cone, 2, MECH_AMOUNT_MASS, 2.0, &p), MECH_STATUS_OK);
    CHECK_NEAR(p.center_of_mass.z, 1.0, 0.0);
    CHECK_NEAR(entry(&p.inertia_about_com, 2, 2), 0.3 * 2.0, 4 * EPS);

    double torus[2] = {2.0, 0.5};
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_TORUS, torus, 2, MECH_AMOUNT_MASS, 1.0, &p), MECH_STATUS_OK);
    CHECK_NEAR(entry(&p.inertia_about_com, 2, 2), 4.0 + 0.75 * 0.25, 8 * EPS);

    /* Each kind with its dimension count builds a valid body. */
    const int kinds[12] = {MECH_PRIMITIVE_POINT,     MECH_PRIMITIVE_ROD,      MECH_PRIMITIVE_RECTANGLE_LAMINA,
                           MECH_PRIMITIVE_DISC_LAMINA, MECH_PRIMITIVE_SPHERE, MECH_PRIMITIVE_ELLIPSOID,
                           MECH_PRIMITIVE_BOX,       MECH_PRIMITIVE_CYLINDER, MECH_PRIMITIVE_CONE,
                           MECH_PRIMITIVE_CAPSULE,   MECH_PRIMITIVE_TORUS,    MECH_PRIMITIVE_HEMISPHERE};
    const size_t counts[12] = {0, 1, 2, 1, 1, 3, 3, 2, 2, 2, 2, 1};
    const int classes[12] = {MECH_INERTIA_POINT, MECH_INERTIA_LINEAR, MECH_INERTIA_PLANAR, MECH_INERTIA_PLANAR,
                             MECH_INERTIA_SOLID, MECH_INERTIA_SOLID,  MECH_INERTIA_SOLID,  MECH_INERTIA_SOLID,
                             MECH_INERTIA_SOLID, MECH_INERTIA_SOLID,  MECH_INERTIA_SOLID,  MECH_INERTIA_SOLID};
    double dims[3] = {2.0, 1.0, 0.5};
    for (int k = 0; k < 12; ++k) {
        CHECK_STATUS(mech_mass_primitive(kinds[k], counts[k] ? dims : NULL, counts[k], MECH_AMOUNT_MASS, 1.5, &p),
                     MECH_STATUS_OK);
        CHECK_NEAR(p.mass, 1.5, 0.0);
        mech_mass_validity_t v;
        CHECK_STATUS(mech_mass_check(&p, 0.0, &v), MECH_STATUS_OK);
        CHECK(v.issues == 0);
        CHECK(v.inertia_class == classes[k]);
    }

    mech_mass_properties_t s;
    FILL_SENTINEL(&s, sizeof s);
    CHECK_STATUS(mech_mass_primitive(99, &r, 1, MECH_AMOUNT_MASS, 1.0, &s), MECH_STATUS_BAD_ENUM);
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_SPHERE, &r, 1, 7, 1.0, &s), MECH_STATUS_BAD_ENUM);
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_SPHERE, cyl, 2, MECH_AMOUNT_MASS, 1.0, &s),
                 MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_SPHERE, NULL, 1, MECH_AMOUNT_MASS, 1.0, &s),
                 MECH_STATUS_NULL_POINTER);
    double neg = -1.0, nan = NAN;
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_SPHERE, &neg, 1, MECH_AMOUNT_MASS, 1.0, &s),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_SPHERE, &nan, 1, MECH_AMOUNT_MASS, 1.0, &s),
                 MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_SPHERE, &r, 1, MECH_AMOUNT_DENSITY, 0.0, &s),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_SPHERE, &r, 1, MECH_AMOUNT_MASS, INFINITY, &s),
                 MECH_STATUS_NON_FINITE);
    double bad_torus[2] = {1.0, 2.0};
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_TORUS, bad_torus, 2, MECH_AMOUNT_MASS, 1.0, &s),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK(mech_untouched(&s, sizeof s));
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_SPHERE, &r, 1, MECH_AMOUNT_MASS, 1.0, NULL),
                 MECH_STATUS_NULL_POINTER);
}

static void combine_subtract_transform(void) {
    /* Three stacked unit cubes equal one 1×3×1 box. */
    mech_mass_properties_t cube = make_box(1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0);
    mech_mass_properties_t parts[3] = {cube, cube, cube};
    mech_quat_t q[3] = {{1, 0, 0, 0}, {1, 0, 0, 0}, {1, 0, 0, 0}};
    mech_vec3_t t[3] = {{0.5, 0.5, 0.5}, {0.5, 1.5, 0.5}, {0.5, 2.5, 0.5}};
    mech_mass_properties_t sum;
    CHECK_STATUS(mech_mass_combine(parts, q, t, 3, &sum), MECH_STATUS_OK);
    mech_mass_properties_t tall = make_box(3.0, 1.0, 3.0, 1.0, 0.5, 1.5, 0.5);
    CHECK_NEAR(sum.mass, 3.0, 0.0);
    CHECK_NEAR(sum.center_of_mass.y, 1.5, 4 * EPS);
    for (int i = 0; i < 9; ++i) CHECK_NEAR(sum.inertia_about_com.m[i], tall.inertia_about_com.m[i], 16 * EPS);

    /* Without poses: the same parts already placed. */
    for (int i = 0; i < 3; ++i) parts[i].center_of_mass = t[i];
    mech_mass_properties_t sum2;
    CHECK_STATUS(mech_mass_combine(parts, NULL, NULL, 3, &sum2), MECH_STATUS_OK);
    for (int i = 0; i < 9; ++i) CHECK_NEAR(sum2.inertia_about_com.m[i], tall.inertia_about_com.m[i], 16 * EPS);

    /* Removing the top cube leaves a 1×2×1 box. */
    mech_mass_properties_t rest;
    CHECK_STATUS(mech_mass_subtract(&sum, &parts[2], &rest), MECH_STATUS_OK);
    mech_mass_properties_t two = make_box(2.0, 1.0, 2.0, 1.0, 0.5, 1.0, 0.5);
    CHECK_NEAR(rest.center_of_mass.y, 1.0, 8 * EPS);
    for (int i = 0; i < 9; ++i) CHECK_NEAR(rest.inertia_about_com.m[i], two.inertia_about_com.m[i], 32 * EPS);

    /* A quarter turn about z swaps I_xx and I_yy and moves the centre. */
    mech_mass_properties_t b = make_box(1.0, 1.0, 2.0, 3.0, 1.0, 0.0, 0.0);
    mech_quat_t qz = {sqrt(0.5), 0.0, 0.0, sqrt(0.5)};
    mech_vec3_t tz = {0.0, 0.0, 5.0};
    mech_mass_properties_t moved;
    CHECK_STATUS(mech_mass_transform(&b, &qz, &tz, &moved), MECH_STATUS_OK);
    CHECK_NEAR(moved.center_of_mass.x, 0.0, 4 * EPS);
    CHECK_NEAR(moved.center_of_mass.y, 1.0, 4 * EPS);
    CHECK_NEAR(moved.center_of_mass.z, 5.0, 0.0);
    CHECK_NEAR(entry(&moved.inertia_about_com, 0, 0), entry(&b.inertia_about_com, 1, 1), 8 * EPS);
    CHECK_NEAR(entry(&moved.inertia_about_com, 1, 1), entry(&b.inertia_about_com, 0, 0), 8 * EPS);

    mech_mass_properties_t s;
    FILL_SENTINEL(&s, sizeof s);
    CHECK_STATUS(mech_mass_combine(parts, q, t, 0, &s), MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_mass_combine(NULL, NULL, NULL, 3, &s), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_mass_combine(parts, q, NULL, 3, &s), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_mass_combine(parts, NULL, t, 3, &s), MECH_STATUS_NULL_POINTER);
    mech_quat_t qbad[3] = {{1, 0, 0, 0}, {2, 0, 0, 0}, {1, 0, 0, 0}};
    CHECK_STATUS(mech_mass_combine(parts, qbad, t, 3, &s), MECH_STATUS_INVALID_ARGUMENT);
    mech_vec3_t tnan[3] = {{0, 0, 0}, {NAN, 0, 0}, {0, 0, 0}};
    CHECK_STATUS(mech_mass_combine(parts, q, tnan, 3, &s), MECH_STATUS_NON_FINITE);
    parts[1].mass = 0.0;
    CHECK_STATUS(mech_mass_combine(parts, q, t, 3, &s), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_mass_subtract(&cube, &sum, &s), MECH_STATUS_INVALID_ARGUMENT);
    mech_mass_properties_t far_hole = make_box(0.5, 1.0, 1.0, 1.0, 10.0, 0.0, 0.0);
    CHECK_STATUS(mech_mass_subtract(&cube, &far_hole, &s), MECH_STATUS_NOT_POSITIVE_DEFINITE);
    CHECK_STATUS(mech_mass_subtract(&cube, NULL, &s), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_mass_transform(&b, &qbad[1], &tz, &s), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_mass_transform(&b, &qz, NULL, &s), MECH_STATUS_NULL_POINTER);
    /* An asymmetric tensor is refused, not silently replaced by its symmetric part; one
       asymmetric within rounding of its trace is accepted. */
    mech_mass_properties_t skew = b;
    skew.inertia_about_com.m[1] += 1e-3;
    CHECK_STATUS(mech_mass_transform(&skew, &qz, &tz, &s), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_mass_subtract(&skew, &far_hole, &s), MECH_STATUS_INVALID_ARGUMENT);
    CHECK(mech_untouched(&s, sizeof s));
    mech_mass_properties_t nearly = b;
    nearly.inertia_about_com.m[1] += 1e-14;
    CHECK_STATUS(mech_mass_transform(&nearly, &qz, &tz, &s), MECH_STATUS_OK);
    CHECK_STATUS(mech_mass_transform(&b, &qz, &tz, NULL), MECH_STATUS_NULL_POINTER);
}

static void lines_and_principal_axes(void) {
    /* Rod of length 2 along z about a perpendicular axis through its end: m L²/3. */
    double len = 2.0;
    mech_mass_properties_t rod;
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_ROD, &len, 1, MECH_AMOUNT_MASS, 3.0, &rod), MECH_STATUS_OK);
    mech_vec3_t end = {0, 0, -1}, dir = {0, 7, 0}, zero = {0, 0, 0};
    double i;
    CHECK_STATUS(mech_mass_moment_about_line(&rod, &end, &dir, &i), MECH_STATUS_OK);
    CHECK_NEAR(i, 4.0, 8 * EPS);
    double is = 0;
    FILL_SENTINEL(&is, sizeof is);
    CHECK_STATUS(mech_mass_moment_about_line(&rod, &end, &zero, &is), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_mass_moment_about_line(&rod, NULL, &dir, &is), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&is, sizeof is));

    /* Disc in the xy plane: moments m r²/4, m r²/4, m r²/2 and the identity frame. */
    double r = 1.0;
    mech_mass_properties_t disc;
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_DISC_LAMINA, &r, 1, MECH_AMOUNT_MASS, 4.0, &disc),
                 MECH_STATUS_OK);
    mech_vec3_t moments;
    mech_mat3_t axes;
    CHECK_STATUS(mech_mass_principal_axes(&disc, &moments, &axes), MECH_STATUS_OK);
    CHECK_NEAR(moments.x, 1.0, 0.0);
    CHECK_NEAR(moments.y, 1.0, 0.0);
    CHECK_NEAR(moments.z, 2.0, 0.0);
    for (int k = 0; k < 9; ++k) CHECK_NEAR(axes.m[k], (k % 4 == 0) ? 1.0 : 0.0, 0.0);
    /* A box with distinct moments: sorted, right-handed. */
    mech_mass_properties_t b = make_box(1.0, 3.0, 1.0, 2.0, 0, 0, 0);
    CHECK_STATUS(mech_mass_principal_axes(&b, &moments, &axes), MECH_STATUS_OK);
    CHECK(moments.x <= moments.y && moments.y <= moments.z);
    CHECK_NEAR(moments.x, 5.0 / 12.0, 4 * EPS);
    CHECK_NEAR(fabs(entry(&axes, 1, 2)), 1.0, 4 * EPS); /* largest moment about y (the short side 1) */

    mech_vec3_t ms;
    mech_mat3_t as;
    FILL_SENTINEL(&ms, sizeof ms);
    FILL_SENTINEL(&as, sizeof as);
    mech_mass_properties_t nanp = b;
    nanp.inertia_about_com.m[3] = NAN;
    CHECK_STATUS(mech_mass_principal_axes(&nanp, &ms, &as), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_mass_principal_axes(&b, NULL, &as), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_mass_principal_axes(&b, &ms, NULL), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&ms, sizeof ms) && mech_untouched(&as, sizeof as));
}

static void validity_and_repair(void) {
    mech_mass_properties_t p = make_box(1.0, 1.0, 1.0, 1.0, 0, 0, 0);
    p.inertia_about_com.m[8] = 3.0; /* I_zz too large: triangle inequality */
    p.inertia_about_com.m[3] = 0.01; /* J_01 without J_10: not symmetric */
    mech_mass_validity_t v;
    CHECK_STATUS(mech_mass_check(&p, 0.0, &v), MECH_STATUS_OK);
    CHECK(v.issues == (MECH_MASS_ISSUE_TRIANGLE_INEQUALITY | MECH_MASS_ISSUE_NOT_SYMMETRIC));
    CHECK(v.inertia_class == MECH_INERTIA_INVALID);
    mech_mass_properties_t neg = make_box(-1.0, 1.0, 1.0, 1.0, 0, 0, 0);
    CHECK_STATUS(mech_mass_check(&neg, 0.0, &v), MECH_STATUS_OK);
    CHECK(v.issues & MECH_MASS_ISSUE_NEGATIVE_MASS);
    CHECK(v.issues & MECH_MASS_ISSUE_NOT_POSITIVE_SEMIDEFINITE);
    mech_mass_properties_t nanp = make_box(1.0, 1.0, 1.0, 1.0, 0, 0, 0);
    nanp.inertia_about_com.m[0] = NAN;
    CHECK_STATUS(mech_mass_check(&nanp, 0.0, &v), MECH_STATUS_OK);
    CHECK(v.issues == MECH_MASS_ISSUE_NON_FINITE);
    /* An asymmetric tensor near f64::MAX: J + Jᵀ would overflow, the moments must not.
       Symmetric part diag(1e308) with 2e307 off the diagonal: moments 0.8e308, 1e308, 1.2e308. */
    mech_mass_properties_t huge = make_box(1.0, 1.0, 1.0, 1.0, 0, 0, 0);
    for (int k = 0; k < 9; ++k) huge.inertia_about_com.m[k] = 0.0;
    huge.inertia_about_com.m[0] = huge.inertia_about_com.m[4] = huge.inertia_about_com.m[8] = 1e308;
    huge.inertia_about_com.m[3] = 1e307;
    huge.inertia_about_com.m[1] = 3e307;
    CHECK_STATUS(mech_mass_check(&huge, 0.0, &v), MECH_STATUS_OK);
    CHECK(v.issues & MECH_MASS_ISSUE_NOT_SYMMETRIC);
    CHECK(fabs(v.moments.x - 0.8e308) <= 1e-14 * 1e308);
    CHECK(fabs(v.moments.y - 1e308) <= 1e-14 * 1e308);
    CHECK(fabs(v.moments.z - 1.2e308) <= 1e-14 * 1e308);

    mech_mass_properties_t fixed;
    double change = -1.0;
    CHECK_STATUS(mech_mass_repair(&p, 0.0, &fixed, &change), MECH_STATUS_OK);
    CHECK(change > 0.0);
    CHECK_STATUS(mech_mass_check(&fixed, 0.0, &v), MECH_STATUS_OK);
    CHECK(v.issues == 0);
    CHECK(v.inertia_class == MECH_INERTIA_PLANAR); /* clamped onto I1 + I2 = I3 */
    CHECK_STATUS(mech_mass_repair(&fixed, 0.0, &fixed, NULL), MECH_STATUS_OK);

    mech_mass_validity_t vs;
    mech_mass_properties_t s;
    FILL_SENTINEL(&vs, sizeof vs);
    FILL_SENTINEL(&s, sizeof s);
    CHECK_STATUS(mech_mass_check(&p, -1.0, &vs), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_mass_check(&p, NAN, &vs), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_mass_check(NULL, 0.0, &vs), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&vs, sizeof vs));
    CHECK_STATUS(mech_mass_check(&p, 0.0, NULL), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_mass_repair(&neg, 0.0, &s, NULL), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_mass_repair(&nanp, 0.0, &s, NULL), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_mass_repair(&p, 0.0, NULL, NULL), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&s, sizeof s));
}

static void momenta_and_energy(void) {
    /* Unit-mass sphere spinning about z while its centre moves along x. */
    double r = 1.0;
    mech_mass_properties_t s;
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_SPHERE, &r, 1, MECH_AMOUNT_MASS, 1.0, &s), MECH_STATUS_OK);
    mech_vec3_t v = {2.0, 0.0, 0.0}, w = {0.0, 0.0, 5.0}, a = {0.0, -1.0, 0.0};
    double t;
    mech_vec3_t p;
    CHECK_STATUS(mech_mass_kinetic_energy(&s, &v, &w, &t, &p), MECH_STATUS_OK);
    CHECK_NEAR(t, 0.5 * 4.0 + 0.5 * 0.4 * 25.0, 8 * EPS);
    CHECK_NEAR(p.x, 2.0, 0.0);
    CHECK_STATUS(mech_mass_kinetic_energy(&s, &v, &w, &t, NULL), MECH_STATUS_OK);
    /* Rolling without slipping on the plane y = −1 ... D_A = J0 ω + (x0 − a) × m v0 */
    mech_vec3_t d;
    CHECK_STATUS(mech_mass_angular_momentum(&s, &a, &v, &w, &d), MECH_STATUS_OK);
    CHECK_NEAR(d.x, 0.0, 0.0);
    CHECK_NEAR(d.z, 0.4 * 5.0 - 2.0, 8 * EPS);

    double ts;
    mech_vec3_t ds;
    FILL_SENTINEL(&ts, sizeof ts);
    FILL_SENTINEL(&ds, sizeof ds);
    mech_vec3_t bad = {NAN, 0, 0};
    CHECK_STATUS(mech_mass_kinetic_energy(&s, &bad, &w, &ts, NULL), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_mass_kinetic_energy(&s, &v, &w, NULL, NULL), MECH_STATUS_NULL_POINTER);
    mech_vec3_t huge = {1e200, 0, 0};
    CHECK_STATUS(mech_mass_kinetic_energy(&s, &huge, &w, &ts, NULL), MECH_STATUS_OUT_OF_RANGE);
    CHECK_STATUS(mech_mass_angular_momentum(&s, &a, &v, &bad, &ds), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_mass_angular_momentum(&s, NULL, &v, &w, &ds), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&ts, sizeof ts) && mech_untouched(&ds, sizeof ds));
    CHECK_STATUS(mech_mass_angular_momentum(&s, &a, &v, &w, NULL), MECH_STATUS_NULL_POINTER);
}

/* A 1×2×3 box centred at (c, c, c): 8 vertices, 12 outward triangles. */
static void box_mesh(double c, double v[24], uint32_t tri[36]) {
    const double size[3] = {1.0, 2.0, 3.0};
    for (int k = 0; k < 8; ++k) {
        for (int axis = 0; axis < 3; ++axis) {
            double sign = (k & (1 << axis)) ? 0.5 : -0.5;
            v[3 * k + axis] = c + sign * size[axis];
        }
    }
    const uint32_t t[36] = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                            2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
    memcpy(tri, t, sizeof t);
}

static void meshes(void) {
    double v[24];
    uint32_t tri[36];
    box_mesh(1e6, v, tri);
    mech_mass_properties_t p;
    mech_mesh_report_t rep;
    CHECK_STATUS(mech_mass_mesh(v, 8, tri, 12, MECH_AMOUNT_DENSITY, 2.0, NULL, &p, &rep), MECH_STATUS_OK);
    CHECK_NEAR(p.mass, 12.0, 64 * EPS);
    CHECK_NEAR(p.center_of_mass.x, 1e6, 4 * EPS * 1e6);
    CHECK_NEAR(entry(&p.inertia_about_com, 0, 0), 12.0 * (4.0 + 9.0) / 12.0, 64 * EPS * 13.0);
    CHECK_NEAR(entry(&p.inertia_about_com, 2, 2), 12.0 * (1.0 + 4.0) / 12.0, 64 * EPS * 13.0);
    CHECK_NEAR(entry(&p.inertia_about_com, 0, 1), 0.0, 64 * EPS * 13.0);
    CHECK(rep.model == MECH_MESH_SOLID && rep.flipped == 0);
    CHECK_NEAR(rep.measure, 6.0, 64 * EPS);
    CHECK(rep.triangles == 12 && rep.boundary_edges == 0 && rep.degenerate_triangles == 0);
    CHECK(rep.relative_error_bound > 0.0 && rep.relative_error_bound < 1e-10);
    CHECK_STATUS(mech_mass_mesh(v, 8, tri, 12, MECH_AMOUNT_MASS, 5.0, NULL, &p, NULL), MECH_STATUS_OK);
    CHECK_NEAR(p.mass, 5.0, 0.0);

    /* Inside out: flipped by default, rejected on request. */
    uint32_t inv[36];
    for (int k = 0; k < 12; ++k) {
        inv[3 * k] = tri[3 * k];
        inv[3 * k + 1] = tri[3 * k + 2];
        inv[3 * k + 2] = tri[3 * k + 1];
    }
    CHECK_STATUS(mech_mass_mesh(v, 8, inv, 12, MECH_AMOUNT_DENSITY, 2.0, NULL, &p, &rep), MECH_STATUS_OK);
    CHECK(rep.flipped == 1);
    CHECK_NEAR(p.mass, 12.0, 64 * EPS);
    mech_mesh_options_t opts = {MECH_MESH_SOLID, MECH_OPEN_MESH_REJECT, MECH_INSIDE_OUT_REJECT, MECH_DEGENERATE_SKIP};
    mech_mass_properties_t s;
    mech_mesh_report_t rs;
    FILL_SENTINEL(&s, sizeof s);
    FILL_SENTINEL(&rs, sizeof rs);
    CHECK_STATUS(mech_mass_mesh(v, 8, inv, 12, MECH_AMOUNT_DENSITY, 2.0, &opts, &s, &rs),
                 MECH_STATUS_INVALID_ARGUMENT);

    /* Open: rejected by default (3 boundary edges in the message), or taken as a shell. */
    CHECK_STATUS(mech_mass_mesh(v, 8, tri, 11, MECH_AMOUNT_DENSITY, 2.0, NULL, &s, &rs),
                 MECH_STATUS_INVALID_ARGUMENT);
    char msg[256];
    mech_last_error(msg, sizeof msg);
    CHECK(strstr(msg, "3 boundary edges") != NULL);
    mech_mesh_options_t shell = {MECH_MESH_SOLID, MECH_OPEN_MESH_SHELL, MECH_INSIDE_OUT_FLIP, MECH_DEGENERATE_SKIP};
    CHECK_STATUS(mech_mass_mesh(v, 8, tri, 11, MECH_AMOUNT_DENSITY, 1.0, &shell, &p, &rep), MECH_STATUS_OK);
    CHECK(rep.model == MECH_MESH_SHELL && rep.boundary_edges == 3);
    CHECK_NEAR(rep.measure, 22.0 - 3.0, 64 * EPS * 22.0); /* the box area 22 minus half the 2×3 face at x = +0.5 */

    /* Bad input. */
    double vnan[24];
    memcpy(vnan, v, sizeof v);
    vnan[7] = NAN;
    CHECK_STATUS(mech_mass_mesh(vnan, 8, tri, 12, MECH_AMOUNT_DENSITY, 1.0, NULL, &s, &rs), MECH_STATUS_NON_FINITE);
    uint32_t range[36];
    memcpy(range, tri, sizeof range);
    range[20] = 8;
    CHECK_STATUS(mech_mass_mesh(v, 8, range, 12, MECH_AMOUNT_DENSITY, 1.0, NULL, &s, &rs),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_mass_mesh(v, 8, tri, 12, MECH_AMOUNT_DENSITY, -1.0, NULL, &s, &rs),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_mass_mesh(v, 8, tri, 12, 5, 1.0, NULL, &s, &rs), MECH_STATUS_BAD_ENUM);
    mech_mesh_options_t bad_opts = {MECH_MESH_SOLID, 9, MECH_INSIDE_OUT_FLIP, MECH_DEGENERATE_SKIP};
    CHECK_STATUS(mech_mass_mesh(v, 8, tri, 12, MECH_AMOUNT_DENSITY, 1.0, &bad_opts, &s, &rs), MECH_STATUS_BAD_ENUM);
    CHECK_STATUS(mech_mass_mesh(v, 8, tri, 0, MECH_AMOUNT_DENSITY, 1.0, NULL, &s, &rs), MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_mass_mesh(NULL, 8, tri, 12, MECH_AMOUNT_DENSITY, 1.0, NULL, &s, &rs),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_mass_mesh(v, 8, NULL, 12, MECH_AMOUNT_DENSITY, 1.0, NULL, &s, &rs),
                 MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_mass_mesh(v, SIZE_MAX, tri, 12, MECH_AMOUNT_DENSITY, 1.0, NULL, &s, &rs),
                 MECH_STATUS_BAD_DIMENSION);
    /* A closed, two-sided flat triangle encloses no volume. */
    double flat_v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    uint32_t flat_t[6] = {0, 1, 2, 0, 2, 1};
    CHECK_STATUS(mech_mass_mesh(flat_v, 3, flat_t, 2, MECH_AMOUNT_DENSITY, 1.0, NULL, &s, &rs),
                 MECH_STATUS_INVALID_ARGUMENT);
    /* Degenerate triangles: skipped and counted, or rejected. */
    uint32_t with_deg[39];
    memcpy(with_deg, tri, sizeof tri);
    with_deg[36] = 3;
    with_deg[37] = 3;
    with_deg[38] = 5;
    CHECK_STATUS(mech_mass_mesh(v, 8, with_deg, 13, MECH_AMOUNT_DENSITY, 2.0, NULL, &p, &rep), MECH_STATUS_OK);
    CHECK(rep.degenerate_triangles == 1);
    mech_mesh_options_t strict = {MECH_MESH_SOLID, MECH_OPEN_MESH_REJECT, MECH_INSIDE_OUT_FLIP, MECH_DEGENERATE_REJECT};
    CHECK_STATUS(mech_mass_mesh(v, 8, with_deg, 13, MECH_AMOUNT_DENSITY, 2.0, &strict, &s, &rs),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK(mech_untouched(&s, sizeof s) && mech_untouched(&rs, sizeof rs));
    CHECK_STATUS(mech_mass_mesh(v, 8, tri, 12, MECH_AMOUNT_DENSITY, 1.0, NULL, NULL, &rs), MECH_STATUS_NULL_POINTER);
}

/* The box as a triangle soup (every corner its own vertex, as in an STL file), each copy of a
 * corner moved along x by 0, 5e-9 or 1e-8 (m): open for mech_mass_mesh, welded closed by
 * mech_mass_mesh_welded at the default tolerance 1e-8 × √14 ≈ 3.7e-8 m. */
static void welded_mesh(void) {
    double v[24];
    uint32_t tri[36];
    box_mesh(1e6, v, tri);
    double soup[108];
    uint32_t idx[36];
    for (int c = 0; c < 36; ++c) {
        for (int axis = 0; axis < 3; ++axis) {
            soup[3 * c + axis] = v[3 * tri[c] + axis];
        }
        soup[3 * c] += 5e-9 * (double)(c % 3);
        idx[c] = (uint32_t)c;
    }
    mech_mass_properties_t p;
    mech_mesh_report_t rep;
    mech_weld_report_t w;
    CHECK_STATUS(mech_mass_mesh(soup, 36, idx, 12, MECH_AMOUNT_DENSITY, 2.0, NULL, &p, &rep),
                 MECH_STATUS_INVALID_ARGUMENT);
    FILL_SENTINEL(&w, sizeof w);
    CHECK_STATUS(mech_mass_mesh_welded(soup, 36, idx, 12, MECH_DEFAULT_WELD_TOLERANCE, MECH_AMOUNT_DENSITY, 2.0,
                                       NULL, &p, &rep, &w),
                 MECH_STATUS_OK);
    CHECK(w.vertices_before == 36 && w.vertices_after == 8 && w.vertices_welded == 28 && w.triangles_dropped == 0);
    CHECK(w.relative_tolerance == MECH_DEFAULT_WELD_TOLERANCE);
    CHECK_NEAR(w.tolerance, 1e-8 * sqrt(14.0), 1e-6 * 1e-8 * sqrt(14.0));
    CHECK(w.max_displacement > 0.0 && w.max_displacement <= w.tolerance);
    CHECK(rep.triangles == 12 && rep.boundary_edges == 0);
    /* Every corner within 1e-8 m of the box: volume within 22e-8 m³ (area × shift) of 6. */
    CHECK_NEAR(p.mass, 12.0, 2.0 * 22e-8);
    CHECK_NEAR(entry(&p.inertia_about_com, 0, 0), 12.0 * (4.0 + 9.0) / 12.0, 1e-6);
    /* Off: only identical positions merge, the jittered soup stays open. */
    CHECK_STATUS(mech_mass_mesh_welded(soup, 36, idx, 12, 0.0, MECH_AMOUNT_DENSITY, 2.0, NULL, &p, &rep, &w),
                 MECH_STATUS_INVALID_ARGUMENT);
    /* Bad tolerances; a NULL weld report is allowed. */
    CHECK_STATUS(mech_mass_mesh_welded(soup, 36, idx, 12, -1e-8, MECH_AMOUNT_DENSITY, 2.0, NULL, &p, &rep, &w),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_mass_mesh_welded(soup, 36, idx, 12, NAN, MECH_AMOUNT_DENSITY, 2.0, NULL, &p, &rep, &w),
                 MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_mass_mesh_welded(soup, 36, idx, 12, 1e-8, MECH_AMOUNT_DENSITY, 2.0, NULL, &p, NULL, NULL),
                 MECH_STATUS_OK);
    CHECK_STATUS(mech_mass_mesh_welded(soup, 36, idx, 12, 1e-8, MECH_AMOUNT_DENSITY, 2.0, NULL, NULL, NULL, NULL),
                 MECH_STATUS_NULL_POINTER);
}

/* mech_mesh_options_default writes the options a NULL pointer selects: the same properties and
 * report, bit for bit, for an inside-out box far from the origin (flipped by default). */
static void mesh_options_default(void) {
    mech_mesh_options_t o;
    FILL_SENTINEL(&o, sizeof o);
    CHECK_STATUS(mech_mesh_options_default(&o), MECH_STATUS_OK);
    CHECK(o.model == MECH_MESH_SOLID && o.open_mesh == MECH_OPEN_MESH_REJECT);
    CHECK(o.inside_out == MECH_INSIDE_OUT_FLIP && o.degenerate == MECH_DEGENERATE_SKIP);
    CHECK_STATUS(mech_mesh_options_default(NULL), MECH_STATUS_NULL_POINTER);

    double v[24];
    uint32_t tri[36], inv[36];
    box_mesh(1e6, v, tri);
    for (int k = 0; k < 12; ++k) {
        inv[3 * k] = tri[3 * k];
        inv[3 * k + 1] = tri[3 * k + 2];
        inv[3 * k + 2] = tri[3 * k + 1];
    }
    mech_mass_properties_t by_null, by_default;
    mech_mesh_report_t rep_null, rep_default;
    CHECK_STATUS(mech_mass_mesh(v, 8, inv, 12, MECH_AMOUNT_DENSITY, 2.0, NULL, &by_null, &rep_null), MECH_STATUS_OK);
    CHECK_STATUS(mech_mass_mesh(v, 8, inv, 12, MECH_AMOUNT_DENSITY, 2.0, &o, &by_default, &rep_default),
                 MECH_STATUS_OK);
    CHECK(rep_null.flipped == 1 && rep_default.flipped == 1);
    CHECK(memcmp(&by_null, &by_default, sizeof by_null) == 0);
    CHECK(memcmp(&rep_null, &rep_default, sizeof rep_null) == 0);
}

/* A deforming box: the report of the first call carries the topology to later calls on the same
 * triangles, whose results equal a fresh mech_mass_mesh bit for bit and the closed form. */
static void deforming_mesh(void) {
    double v[24];
    uint32_t tri[36];
    box_mesh(0.0, v, tri);
    mech_mass_properties_t first, checked, reused;
    mech_mesh_report_t earlier, rep_checked, rep_reused;
    CHECK_STATUS(mech_mass_mesh(v, 8, tri, 12, MECH_AMOUNT_DENSITY, 2.0, NULL, &first, &earlier), MECH_STATUS_OK);
    for (int k = 0; k < 8; ++k) {
        v[3 * k] *= 2.0; /* now 2 × 2 × 3 */
    }
    CHECK_STATUS(mech_mass_mesh(v, 8, tri, 12, MECH_AMOUNT_DENSITY, 2.0, NULL, &checked, &rep_checked),
                 MECH_STATUS_OK);
    CHECK_STATUS(mech_mass_mesh_same_connectivity(v, 8, tri, 12, MECH_AMOUNT_DENSITY, 2.0, NULL, &earlier, &reused,
                                                  &rep_reused),
                 MECH_STATUS_OK);
    CHECK(memcmp(&checked, &reused, sizeof checked) == 0);
    CHECK(memcmp(&rep_checked, &rep_reused, sizeof rep_checked) == 0);
    CHECK_NEAR(reused.mass, 24.0, 64 * EPS * 24.0);
    CHECK_NEAR(entry(&reused.inertia_about_com, 0, 0), 24.0 * (4.0 + 9.0) / 12.0, 64 * EPS * 26.0);
    CHECK_NEAR(entry(&reused.inertia_about_com, 2, 2), 24.0 * (4.0 + 4.0) / 12.0, 64 * EPS * 26.0);

    /* Errors: nothing written. */
    mech_mass_properties_t s;
    mech_mesh_report_t rs;
    FILL_SENTINEL(&s, sizeof s);
    FILL_SENTINEL(&rs, sizeof rs);
    CHECK_STATUS(mech_mass_mesh_same_connectivity(v, 8, tri, 12, MECH_AMOUNT_DENSITY, 2.0, NULL, NULL, &s, &rs),
                 MECH_STATUS_NULL_POINTER);
    mech_mesh_report_t other = earlier;
    other.triangles = 11;
    CHECK_STATUS(mech_mass_mesh_same_connectivity(v, 8, tri, 12, MECH_AMOUNT_DENSITY, 2.0, NULL, &other, &s, &rs),
                 MECH_STATUS_BAD_DIMENSION);
    uint32_t range[36];
    memcpy(range, tri, sizeof range);
    range[4] = 8;
    CHECK_STATUS(mech_mass_mesh_same_connectivity(v, 8, range, 12, MECH_AMOUNT_DENSITY, 2.0, NULL, &earlier, &s, &rs),
                 MECH_STATUS_INVALID_ARGUMENT);
    other = earlier;
    other.boundary_edges = 3; /* an open mesh is still refused as a solid */
    CHECK_STATUS(mech_mass_mesh_same_connectivity(v, 8, tri, 12, MECH_AMOUNT_DENSITY, 2.0, NULL, &other, &s, &rs),
                 MECH_STATUS_INVALID_ARGUMENT);
    v[5] = NAN;
    CHECK_STATUS(mech_mass_mesh_same_connectivity(v, 8, tri, 12, MECH_AMOUNT_DENSITY, 2.0, NULL, &earlier, &s, &rs),
                 MECH_STATUS_NON_FINITE);
    CHECK(mech_untouched(&s, sizeof s) && mech_untouched(&rs, sizeof rs));
}

/* A double pendulum in the xy plane: revolute z joints; link 1 a uniform thin rod of mass m1 and
 * length l1 along its x axis, link 2 a point mass m2 at distance l2 from its joint. Closed forms:
 * A11 = m1 l1²/3 + m2 (l1² + l2² + 2 l1 l2 cos q2), A12 = m2 (l2² + l1 l2 cos q2), A22 = m2 l2²;
 * the energies from the particle and rigid-body velocities directly. */
static void tree_mechanism(void) {
    const double l1 = 0.8, l2 = 0.5, m1 = 1.5, m2 = 0.6;
    const double i1 = m1 * l1 * l1 / 12.0;
    mech_tree_t *tree = NULL;
    CHECK_STATUS(mech_tree_create(&tree), MECH_STATUS_OK);
    mech_mat3_t id;
    memset(&id, 0, sizeof id);
    id.m[0] = id.m[4] = id.m[8] = 1.0;
    mech_vec3_t origin = {0.0, 0.0, 0.0}, link = {l1, 0.0, 0.0}, z = {0.0, 0.0, 1.0};
    size_t b0, b1;
    CHECK_STATUS(mech_tree_add_body(tree, -1, MECH_JOINT_REVOLUTE, &z, &id, &origin, &b0), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_add_body(tree, (int64_t)b0, MECH_JOINT_REVOLUTE, &z, &id, &link, &b1), MECH_STATUS_OK);

    mech_mass_properties_t bodies[2];
    memset(bodies, 0, sizeof bodies);
    bodies[0].mass = m1;
    bodies[0].center_of_mass.x = l1 / 2.0;
    bodies[0].inertia_about_com.m[4] = i1;
    bodies[0].inertia_about_com.m[8] = i1;
    mech_vec3_t tip = {l2, 0.0, 0.0};
    CHECK_STATUS(mech_mass_point(m2, &tip, &bodies[1]), MECH_STATUS_OK);

    double a[4];
    FILL_SENTINEL(a, sizeof a);
    /* Not finalized, then finalized without a state: nothing to compute from. */
    CHECK_STATUS(mech_tree_mass_matrix(tree, bodies, 2, a, 2), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_tree_finalize(tree), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_mass_matrix(tree, bodies, 2, a, 2), MECH_STATUS_INVALID_ARGUMENT);
    CHECK(mech_untouched(a, sizeof a));

    const double q[2] = {0.3, -0.8}, qd[2] = {0.5, 1.1};
    CHECK_STATUS(mech_tree_set_state(tree, q, qd, 2), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_mass_matrix(tree, bodies, 2, a, 2), MECH_STATUS_OK);
    const double c2 = cos(q[1]);
    const double a11 = m1 * l1 * l1 / 3.0 + m2 * (l1 * l1 + l2 * l2 + 2.0 * l1 * l2 * c2);
    const double a12 = m2 * (l2 * l2 + l1 * l2 * c2), a22 = m2 * l2 * l2;
    const double tol = 64 * EPS * a11;
    CHECK_NEAR(a[0], a11, tol);
    CHECK_NEAR(a[1], a12, tol);
    CHECK_NEAR(a[2], a12, tol);
    CHECK_NEAR(a[3], a22, tol);

    /* The handle keeps the last bodies: changed bodies must be seen. Doubling every mass and
     * tensor doubles A exactly; the original bodies give the original A again. */
    mech_mass_properties_t doubled[2] = {bodies[0], bodies[1]};
    for (int b = 0; b < 2; ++b) {
        doubled[b].mass *= 2.0;
        for (int e = 0; e < 9; ++e) doubled[b].inertia_about_com.m[e] *= 2.0;
    }
    double a_doubled[4];
    CHECK_STATUS(mech_tree_mass_matrix(tree, doubled, 2, a_doubled, 2), MECH_STATUS_OK);
    for (int e = 0; e < 4; ++e) CHECK(a_doubled[e] == 2.0 * a[e]);
    double a_again[4];
    CHECK_STATUS(mech_tree_mass_matrix(tree, bodies, 2, a_again, 2), MECH_STATUS_OK);
    for (int e = 0; e < 4; ++e) CHECK(a_again[e] == a[e]);

    /* Positions, point Jacobians and velocities of the rod centre c1 and the bob p2. */
    const double s1 = sin(q[0]), k1 = cos(q[0]), s12 = sin(q[0] + q[1]), k12 = cos(q[0] + q[1]);
    const double c1x = 0.5 * l1 * k1, c1y = 0.5 * l1 * s1;
    const double p2x = l1 * k1 + l2 * k12, p2y = l1 * s1 + l2 * s12;
    const double jc1[2] = {-0.5 * l1 * s1, 0.5 * l1 * k1};          /* ∂c1/∂q1 */
    const double jp1[2] = {-l1 * s1 - l2 * s12, l1 * k1 + l2 * k12}; /* ∂p2/∂q1 */
    const double jp2[2] = {-l2 * s12, l2 * k12};                     /* ∂p2/∂q2 */
    const double vc1[2] = {jc1[0] * qd[0], jc1[1] * qd[0]};
    const double vp2[2] = {jp1[0] * qd[0] + jp2[0] * qd[1], jp1[1] * qd[0] + jp2[1] * qd[1]};

    /* Fixed base: T and p = A q̇. */
    double t, p[2];
    CHECK_STATUS(mech_tree_kinetic_energy(tree, bodies, 2, &t, p, 2), MECH_STATUS_OK);
    const double t_ref = 0.5 * m1 * (vc1[0] * vc1[0] + vc1[1] * vc1[1]) + 0.5 * i1 * qd[0] * qd[0] +
                         0.5 * m2 * (vp2[0] * vp2[0] + vp2[1] * vp2[1]);
    CHECK_NEAR(t, t_ref, 64 * EPS * t_ref);
    CHECK_NEAR(p[0], a11 * qd[0] + a12 * qd[1], 64 * EPS * a11);
    CHECK_NEAR(p[1], a12 * qd[0] + a22 * qd[1], 64 * EPS * a11);

    /* Centre of mass and its Jacobian. */
    const double mt = m1 + m2;
    mech_mass_properties_t system;
    double jac[6];
    CHECK_STATUS(mech_tree_center_of_mass(tree, bodies, 2, &system, jac, 2), MECH_STATUS_OK);
    CHECK_NEAR(system.mass, mt, 4 * EPS * mt);
    CHECK_NEAR(system.center_of_mass.x, (m1 * c1x + m2 * p2x) / mt, 16 * EPS);
    CHECK_NEAR(system.center_of_mass.y, (m1 * c1y + m2 * p2y) / mt, 16 * EPS);
    CHECK_NEAR(system.center_of_mass.z, 0.0, 16 * EPS);
    CHECK_NEAR(jac[0], (m1 * jc1[0] + m2 * jp1[0]) / mt, 16 * EPS);
    CHECK_NEAR(jac[1], (m1 * jc1[1] + m2 * jp1[1]) / mt, 16 * EPS);
    CHECK_NEAR(jac[2], 0.0, 16 * EPS);
    CHECK_NEAR(jac[3], m2 * jp2[0] / mt, 16 * EPS);
    CHECK_NEAR(jac[4], m2 * jp2[1] / mt, 16 * EPS);
    CHECK_NEAR(jac[5], 0.0, 16 * EPS);

    /* The base turns about z at rate W and translates with (vx, vy): drag u(x) = v + W z × x. */
    const double w = 0.7, vx = 0.2, vy = -0.1;
    mech_vec3_t omega0 = {0.0, 0.0, w}, v0 = {vx, vy, 0.0};
    const double uc1[2] = {vx - w * c1y, vy + w * c1x}, up2[2] = {vx - w * p2y, vy + w * p2x};
    const double t0_ref = 0.5 * m1 * (uc1[0] * uc1[0] + uc1[1] * uc1[1]) + 0.5 * i1 * w * w +
                          0.5 * m2 * (up2[0] * up2[0] + up2[1] * up2[1]);
    const double b_ref[2] = {m1 * (jc1[0] * uc1[0] + jc1[1] * uc1[1]) + i1 * w + m2 * (jp1[0] * up2[0] + jp1[1] * up2[1]),
                             m2 * (jp2[0] * up2[0] + jp2[1] * up2[1])};
    const double wc1[2] = {vc1[0] + uc1[0], vc1[1] + uc1[1]}, wp2[2] = {vp2[0] + up2[0], vp2[1] + up2[1]};
    const double total_ref = 0.5 * m1 * (wc1[0] * wc1[0] + wc1[1] * wc1[1]) + 0.5 * i1 * (qd[0] + w) * (qd[0] + w) +
                             0.5 * m2 * (wp2[0] * wp2[0] + wp2[1] * wp2[1]);
    mech_energy_split_t split;
    double b[2], pm[2];
    CHECK_STATUS(mech_tree_energy_split(tree, bodies, 2, &omega0, &v0, &split, b, pm, 2), MECH_STATUS_OK);
    const double et = 64 * EPS * total_ref;
    CHECK_NEAR(split.t2, t_ref, et);
    CHECK_NEAR(split.t0, t0_ref, et);
    CHECK_NEAR(split.t1, b_ref[0] * qd[0] + b_ref[1] * qd[1], et);
    CHECK_NEAR(split.total, total_ref, et);
    CHECK_NEAR(b[0], b_ref[0], 64 * EPS * a11);
    CHECK_NEAR(b[1], b_ref[1], 64 * EPS * a11);
    CHECK_NEAR(pm[0], a11 * qd[0] + a12 * qd[1] + b_ref[0], 64 * EPS * a11);
    CHECK_NEAR(pm[1], a12 * qd[0] + a22 * qd[1] + b_ref[1], 64 * EPS * a11);
    /* A base at rest: T0 = T1 = 0 and T = T2 (9.12). */
    mech_vec3_t still = {0.0, 0.0, 0.0};
    CHECK_STATUS(mech_tree_energy_split(tree, bodies, 2, &still, &still, &split, b, pm, 2), MECH_STATUS_OK);
    CHECK(split.t0 == 0.0 && split.t1 == 0.0 && b[0] == 0.0 && b[1] == 0.0);
    CHECK_NEAR(split.total, t_ref, 64 * EPS * t_ref);

    /* The same moving base prescribed on the tree itself, with its origin moved to p0: body
       velocities now include the drag, so the rigid-body energies of the world velocities sum to
       the total above; T of mech_tree_kinetic_energy stays the relative T2, and the split with
       the same (ω0, v0) is unchanged (it is relative to p0). */
    mech_base_state_t base = {0};
    base.rotation.m[0] = base.rotation.m[4] = base.rotation.m[8] = 1.0;
    base.position = (mech_vec3_t){1.0, 2.0, 0.5};
    base.omega = omega0;
    base.velocity = v0;
    CHECK_STATUS(mech_tree_set_base(tree, &base), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_kinetic_energy(tree, bodies, 2, &t, p, 2), MECH_STATUS_INVALID_ARGUMENT); /* state discarded */
    CHECK_STATUS(mech_tree_set_state(tree, q, qd, 2), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_kinetic_energy(tree, bodies, 2, &t, p, 2), MECH_STATUS_OK);
    CHECK_NEAR(t, t_ref, et);
    mech_mat3_t r_body;
    mech_vec3_t p_body, w_body, v_body, joint_point = {0.0, 0.0, 0.0}, w_tip, v_tip;
    CHECK_STATUS(mech_tree_body_velocity(tree, 0, &bodies[0].center_of_mass, &w_body, &v_body), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_body_velocity(tree, 1, &tip, &w_tip, &v_tip), MECH_STATUS_OK);
    const double t_world = 0.5 * m1 * (v_body.x * v_body.x + v_body.y * v_body.y + v_body.z * v_body.z) +
                           0.5 * i1 * w_body.z * w_body.z +
                           0.5 * m2 * (v_tip.x * v_tip.x + v_tip.y * v_tip.y + v_tip.z * v_tip.z);
    CHECK_NEAR(t_world, total_ref, et);
    CHECK_STATUS(mech_tree_body_pose(tree, 1, &r_body, &p_body), MECH_STATUS_OK);
    CHECK_NEAR(p_body.x, 1.0 + l1 * k1, 16 * EPS);
    CHECK_NEAR(p_body.y, 2.0 + l1 * s1, 16 * EPS);
    CHECK_NEAR(p_body.z, 0.5, 16 * EPS);
    CHECK_STATUS(mech_tree_body_velocity(tree, 0, &joint_point, &w_body, &v_body), MECH_STATUS_OK);
    CHECK_NEAR(w_body.z, w + qd[0], 16 * EPS);
    CHECK_NEAR(v_body.x, vx, 16 * EPS); /* the joint sits at the base origin */
    CHECK_NEAR(v_body.y, vy, 16 * EPS);
    CHECK_STATUS(mech_tree_energy_split(tree, bodies, 2, &omega0, &v0, &split, b, pm, 2), MECH_STATUS_OK);
    CHECK_NEAR(split.t0, t0_ref, et);
    CHECK_NEAR(split.t1, b_ref[0] * qd[0] + b_ref[1] * qd[1], et);
    CHECK_NEAR(split.total, total_ref, et);
    /* Bad base states change nothing: the state stays valid. */
    mech_base_state_t bad_base = base;
    bad_base.velocity.y = NAN;
    CHECK_STATUS(mech_tree_set_base(tree, &bad_base), MECH_STATUS_NON_FINITE);
    bad_base = base;
    bad_base.rotation.m[0] = 2.0;
    CHECK_STATUS(mech_tree_set_base(tree, &bad_base), MECH_STATUS_INVALID_ARGUMENT);
    CHECK_STATUS(mech_tree_set_base(tree, NULL), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_set_base(NULL, &base), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_energy_split(tree, bodies, 2, &omega0, &v0, &split, b, pm, 2), MECH_STATUS_OK);
    CHECK_NEAR(split.total, total_ref, et);
    base.omega = base.velocity = still;
    CHECK_STATUS(mech_tree_set_base(tree, &base), MECH_STATUS_OK);
    CHECK_STATUS(mech_tree_set_state(tree, q, qd, 2), MECH_STATUS_OK);

    /* Error paths: nothing is written. */
    mech_mass_properties_t bad[2] = {bodies[0], bodies[1]};
    FILL_SENTINEL(a, sizeof a);
    CHECK_STATUS(mech_tree_mass_matrix(NULL, bodies, 2, a, 2), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_mass_matrix(tree, NULL, 2, a, 2), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_mass_matrix(tree, bodies, 1, a, 2), MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_tree_mass_matrix(tree, bodies, 3, a, 2), MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_tree_mass_matrix(tree, bodies, 2, a, 1), MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_tree_mass_matrix(tree, bodies, 2, a, 0), MECH_STATUS_BAD_DIMENSION);
    bad[1].mass = NAN;
    CHECK_STATUS(mech_tree_mass_matrix(tree, bad, 2, a, 2), MECH_STATUS_NON_FINITE);
    bad[1].mass = -1.0;
    CHECK_STATUS(mech_tree_mass_matrix(tree, bad, 2, a, 2), MECH_STATUS_INVALID_ARGUMENT);
    char msg[256];
    mech_last_error(msg, sizeof msg);
    CHECK(strstr(msg, "body 1") != NULL);
    bad[1] = bodies[1];
    bad[0].inertia_about_com.m[3] = INFINITY;
    CHECK_STATUS(mech_tree_mass_matrix(tree, bad, 2, a, 2), MECH_STATUS_NON_FINITE);
    bad[0] = bodies[0];
    CHECK(mech_untouched(a, sizeof a));
    CHECK_STATUS(mech_tree_mass_matrix(tree, bodies, 2, NULL, 2), MECH_STATUS_NULL_POINTER);

    double ts, ps[2];
    FILL_SENTINEL(&ts, sizeof ts);
    FILL_SENTINEL(ps, sizeof ps);
    CHECK_STATUS(mech_tree_kinetic_energy(tree, bodies, 2, NULL, ps, 2), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_kinetic_energy(tree, bodies, 2, &ts, NULL, 2), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_kinetic_energy(tree, bodies, 2, &ts, ps, 1), MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_tree_kinetic_energy(tree, bodies, 1, &ts, ps, 2), MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_tree_kinetic_energy(NULL, bodies, 2, &ts, ps, 2), MECH_STATUS_NULL_POINTER);
    CHECK(mech_untouched(&ts, sizeof ts) && mech_untouched(ps, sizeof ps));

    mech_mass_properties_t ss;
    double js[6];
    FILL_SENTINEL(&ss, sizeof ss);
    FILL_SENTINEL(js, sizeof js);
    CHECK_STATUS(mech_tree_center_of_mass(tree, bodies, 2, NULL, js, 2), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_center_of_mass(tree, bodies, 2, &ss, NULL, 2), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_center_of_mass(tree, bodies, 2, &ss, js, 3), MECH_STATUS_BAD_DIMENSION);
    mech_mass_properties_t massless[2];
    memset(massless, 0, sizeof massless);
    CHECK_STATUS(mech_tree_center_of_mass(tree, massless, 2, &ss, js, 2), MECH_STATUS_INVALID_ARGUMENT);
    CHECK(mech_untouched(&ss, sizeof ss) && mech_untouched(js, sizeof js));
    /* Massless links are valid in the mass matrix: A = 0. */
    CHECK_STATUS(mech_tree_mass_matrix(tree, massless, 2, a, 2), MECH_STATUS_OK);
    CHECK(a[0] == 0.0 && a[1] == 0.0 && a[2] == 0.0 && a[3] == 0.0);

    mech_energy_split_t es;
    double bs[2], pms[2];
    FILL_SENTINEL(&es, sizeof es);
    FILL_SENTINEL(bs, sizeof bs);
    FILL_SENTINEL(pms, sizeof pms);
    mech_vec3_t nanv = {0.0, NAN, 0.0};
    CHECK_STATUS(mech_tree_energy_split(tree, bodies, 2, NULL, &v0, &es, bs, pms, 2), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_energy_split(tree, bodies, 2, &omega0, NULL, &es, bs, pms, 2), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_energy_split(tree, bodies, 2, &nanv, &v0, &es, bs, pms, 2), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_tree_energy_split(tree, bodies, 2, &omega0, &nanv, &es, bs, pms, 2), MECH_STATUS_NON_FINITE);
    CHECK_STATUS(mech_tree_energy_split(tree, bodies, 2, &omega0, &v0, NULL, bs, pms, 2), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_energy_split(tree, bodies, 2, &omega0, &v0, &es, NULL, pms, 2), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_energy_split(tree, bodies, 2, &omega0, &v0, &es, bs, NULL, 2), MECH_STATUS_NULL_POINTER);
    CHECK_STATUS(mech_tree_energy_split(tree, bodies, 2, &omega0, &v0, &es, bs, pms, 3), MECH_STATUS_BAD_DIMENSION);
    CHECK_STATUS(mech_tree_energy_split(tree, bad, 1, &omega0, &v0, &es, bs, pms, 2), MECH_STATUS_BAD_DIMENSION);
    CHECK(mech_untouched(&es, sizeof es) && mech_untouched(bs, sizeof bs) && mech_untouched(pms, sizeof pms));
    mech_tree_destroy(tree);
}

/* Results outside the double range: a typed status naming the quantity, never NaN or inf. */
static void extreme_inputs(void) {
    char msg[256];
    mech_mass_properties_t p;
    FILL_SENTINEL(&p, sizeof p);
    /* A sphere of radius 1e308: its moment 0.4 m r^2 is not representable. */
    double big = 1e308;
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_SPHERE, &big, 1, MECH_AMOUNT_MASS, 1.0, &p), MECH_STATUS_OUT_OF_RANGE);
    CHECK(mech_untouched(&p, sizeof p));
    mech_last_error(msg, sizeof msg);
    CHECK(strstr(msg, "sphere moment of inertia") != NULL);
    /* A tiny sphere by density: the mass underflows, and the message says so. */
    double tiny = 1e-120;
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_SPHERE, &tiny, 1, MECH_AMOUNT_DENSITY, 1.0, &p), MECH_STATUS_OUT_OF_RANGE);
    mech_last_error(msg, sizeof msg);
    CHECK(strstr(msg, "underflows to zero") != NULL && strstr(msg, "not finite") == NULL);
    /* Radius 1e103 at density 1e-300: r^3 = 1e309 overflows, the mass 4.19e9 does not. */
    double r = 1e103;
    CHECK_STATUS(mech_mass_primitive(MECH_PRIMITIVE_SPHERE, &r, 1, MECH_AMOUNT_DENSITY, 1e-300, &p), MECH_STATUS_OK);
    CHECK_NEAR(p.mass / (4.0 / 3.0 * 3.14159265358979323846 * 1e9), 1.0, 1e-14);
    CHECK_NEAR(entry(&p.inertia_about_com, 0, 0) / (0.4 * p.mass * 1e206), 1.0, 1e-14);
    /* Principal axes of a tensor with entries near 1e308 (moments representable). */
    mech_mass_properties_t h = make_box(1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0);
    memset(&h.inertia_about_com, 0, sizeof h.inertia_about_com);
    h.inertia_about_com.m[0] = 0.5e308;
    h.inertia_about_com.m[4] = 0.6e308;
    h.inertia_about_com.m[8] = 1.1e308;
    h.inertia_about_com.m[1] = h.inertia_about_com.m[3] = 0.2e308;
    mech_vec3_t moments;
    mech_mat3_t axes;
    CHECK_STATUS(mech_mass_principal_axes(&h, &moments, &axes), MECH_STATUS_OK);
    CHECK(isfinite(moments.x) && isfinite(moments.y) && isfinite(moments.z));
    /* Eigenvalues of [[0.5, 0.2], [0.2, 0.6]]·1e308 are (1.1 ∓ √0.17)/2·1e308, and 1.1e308. */
    CHECK_NEAR(moments.x / 1e308, (1.1 - sqrt(0.17)) / 2.0, 1e-14);
    CHECK_NEAR(moments.y / 1e308, (1.1 + sqrt(0.17)) / 2.0, 1e-14);
    CHECK_NEAR(moments.z / 1e308, 1.1, 1e-14);
    /* An asymmetric tensor is refused. */
    mech_mass_properties_t asym = make_box(1.0, 1.0, 2.0, 3.0, 0.0, 0.0, 0.0);
    asym.inertia_about_com.m[3] += 1e-3;
    FILL_SENTINEL(&moments, sizeof moments);
    CHECK_STATUS(mech_mass_principal_axes(&asym, &moments, &axes), MECH_STATUS_INVALID_ARGUMENT);
    CHECK(mech_untouched(&moments, sizeof moments));
    mech_last_error(msg, sizeof msg);
    CHECK(strstr(msg, "not symmetric") != NULL);
    CHECK(strcmp(mech_status_str(MECH_STATUS_OUT_OF_RANGE), "unknown status") != 0);
}

int main(void) {
    point_and_steiner();
    extreme_inputs();
    primitives();
    combine_subtract_transform();
    lines_and_principal_axes();
    validity_and_repair();
    momenta_and_energy();
    meshes();
    welded_mesh();
    mesh_options_default();
    deforming_mesh();
    tree_mechanism();
    return CHECK_DONE();
}
