#!/usr/bin/env python3
"""Exact ω² of small pencils kept as regression tests in crates/mechanica-modal/tests/wide_range.rs.

Each pencil is given by its stored doubles (A dense, B as its nonzero entries of the upper
triangle); its ω² (the eigenvalues of B x = ω² A x) are computed by mpmath at 400 digits through
the Cholesky factor of A (massless coordinates condensed out exactly) and printed as (hi, lo)
double pairs, ascending, hi + lo equal to ω² to about 32 digits. Output:
tools/modal_found_pencils_reference.out.

Run: python3 tools/modal_found_pencils_reference.py > tools/modal_found_pencils_reference.out
"""

import mpmath as mp

mp.mp.dps = 400

PENCILS = {
    # A refined mode converged to its neighbour's eigenpair in one ordering (coordinates 2, 0, 1, 3).
    "entries from 1e-137 to 1e22": (
        [
            [1.5371442801070985, -0.3408479252830148, -0.6911467285826802, 0.7035937365144491],
            [-0.3408479252830148, 1.2798205931422886, 0.5351544953882694, -0.34600993152707815],
            [-0.6911467285826802, 0.5351544953882694, 2.2062756345359262, -0.7405649181455374],
            [0.7035937365144491, -0.34600993152707815, -0.7405649181455374, 2.0814717394051727],
        ],
        [
            (0, 0, -9.765625e21),
            (0, 1, 188916015625.0),
            (0, 2, -1.40556640625e-32),
            (0, 3, 2.9072265625000003e-28),
            (1, 1, 7.926859425671704e-137),
            (1, 2, -9.765625000000001e-32),
            (1, 3, -9.765625000000001e-32),
            (2, 2, -9.765625000000001e-32),
            (2, 3, 1.22275390625e-12),
            (3, 3, -3.759765625e20),
        ],
    ),
    # Five eigenvalues within 3e-32 of zero under entries of 1e-4: a refined mode's residual
    # bound was taken for the second eigenvalue while its interval met unrefined modes'.
    "five modes near zero": (
        [[1.0010721039250492, 1.3971701264381409e-05, 7.692724466323853e-07, 0.0, -0.00038496311753988266, 3.9674341678619385e-07, 0.00746630784124136, 3.018416464328766e-05], [1.3971701264381409e-05, 1.2004464201852678, 4.973262548446655e-07, 0.0, -0.01638881955295801, 1.3688579201698303e-05, 0.29780180659145117, 4.347600042819977e-05], [7.692724466323853e-07, 4.973262548446655e-07, 2.5540481562018393, 0.0, 2.425163984298706e-06, -0.0017273258417844772, 0.21676191687583923, 0.5931299384683371], [0.0, 0.0, 0.0, 1.001, 0.0, 0.0, 0.0, 0.0], [-0.00038496311753988266, -0.01638881955295801, 2.425163984298706e-06, 0.0, 1.0998843189552425, -7.91158527135849e-06, -0.17283406667411327, -7.91158527135849e-06], [3.9674341678619385e-07, 1.3688579201698303e-05, -0.0017273258417844772, 0.0, -7.91158527135849e-06, 1.001003139488399, 8.362717926502228e-05, -0.00011507514864206314], [0.00746630784124136, 0.29780180659145117, 0.21676191687583923, 0.0, -0.17283406667411327, 8.362717926502228e-05, 2.7515441876128315, 0.3897318113595247], [3.018416464328766e-05, 4.347600042819977e-05, 0.5931299384683371, 0.0, -7.91158527135849e-06, -0.00011507514864206314, 0.3897318113595247, 1.5830786030963062]],
        [(0, 0, 2.4902343749999996e-41), (3, 6, -8.105468750000001e-30), (3, 7, -2.1510742187499998e-29), (4, 4, 0.0001056640625), (4, 5, -9.765625000000001e-32), (4, 6, -9.765625000000001e-32), (4, 7, -9.765625000000001e-32), (5, 5, -9.765625000000001e-32), (5, 6, -9.765625000000001e-32), (5, 7, -2.6100585937499997e-39)],
    ),
    # Five massless coordinates whose stiffness block B00 is nearly singular (condition 1.6e10):
    # the first-order bound of the third mode did not hold, and its refinement was refused.
    "massless coordinates through a nearly singular B00": (
        [[0.0] * 8, [0.0, 1.0] + [0.0] * 6, [0.0] * 8, [0.0] * 3 + [1.0] + [0.0] * 4,
         [0.0] * 4 + [0.00375371938658732] + [0.0] * 3, [0.0] * 8, [0.0] * 8, [0.0] * 8],
        [(0, 0, -8.43780517578125), (0, 1, -0.00030517578125), (0, 2, -0.00030517578125),
         (0, 3, 2.65594482421875), (0, 4, 8.90594482421875), (0, 5, 8.86260986328125),
         (0, 6, 8.86260986328125), (0, 7, 8.86260986328125), (3, 6, 0.00213623046875),
         (5, 7, 3.515625), (6, 6, -2.09564208984375), (6, 7, 3.52935791015625),
         (7, 7, -3.52935791015625)],
    ),
    # Six eigenvalues within 3e-28 of zero (after scaling) under a largest one of 2e-10: the
    # lowest four were bounded by a gap to the unselected modes that their unrefined values did
    # not have.
    "six modes near zero, the lowest four selected": (
        [[1.0120237649658914, -0.2289765551686287, 0.7622260749340057, -0.43085211236029863, -0.2668326608836651, -1.2547426763921976, -0.48041342198848724], [-0.2289765551686287, 3.3095041181201332, 0.2040815893560648, 0.22612688224762678, 0.22860143147408962, 0.6102276127785444, -0.5678917402401567], [0.7622260749340057, 0.2040815893560648, 1.7911876601407524, -0.9422234827652574, -0.9110971540212631, -0.48230474069714546, -0.027302628383040428], [-0.43085211236029863, 0.22612688224762678, -0.9422234827652574, 1.3890334761942025, 0.39497001096606255, 0.5796955274417996, 0.8108259486034513], [-0.2668326608836651, 0.22860143147408962, -0.9110971540212631, 0.39497001096606255, 1.6969582786092754, 0.40319159999489784, -1.1125753866508603], [-1.2547426763921976, 0.6102276127785444, -0.48230474069714546, 0.5796955274417996, 0.40319159999489784, 3.168565905956387, 0.2802895065397024], [-0.48041342198848724, -0.5678917402401567, -0.027302628383040428, 0.8108259486034513, -1.1125753866508603, 0.2802895065397024, 2.3286369464600676]],
        [(0, 0, 2.21611328125e-11), (0, 1, 4.654e-321), (0, 3, -9.765625000000001e-32),
         (0, 4, -9.765625000000001e-32), (0, 5, -2.27509765625e-27),
         (0, 6, -9.765625000000001e-32), (1, 1, 2.0996093749999998e-41)],
    ),
    # A = 0.96 I and couplings up to 1e100: four refined modes near zero chained through one
    # wide interval, and each kept its own residual bound although the sorted values and the
    # sorted eigenvalues did not pair that way (1.2e-68 ± 1.3e21 for the exact 1.63e36).
    "four chained modes under a coupling of 1e100": (
        [[0.9607843137254902 if i == j else 0.0 for j in range(6)] for i in range(6)],
        [(0, 0, -2.5107421875e-38), (2, 3, 1.25009765625e21), (2, 4, -3.0295711161086577e-128),
         (2, 5, -2.74814453125e31), (3, 3, 1.56630859375e36), (3, 4, -0.215107421875),
         (3, 5, 1.9481445312499998e-35), (4, 4, 4.717996333842129e-105), (4, 5, -1e100),
         (5, 5, 1.6709960937500002e-28)],
    ),
    # One subnormal coupling; halving it in the sparse symmetrisation changed the pencil.
    "a subnormal coupling": (
        "diagonal-dominant 7x7",
        [(0, 4, 1.09e-321)],
    ),
}

SUBNORMAL_A_DIAGONAL = [0.0010610388815402985, 0.004910071216523647, 0.0010000065192580223,
                        0.0010000065192580223, 0.0010000065192580223, 0.0010000065192580223,
                        0.0025258844941854477]
SUBNORMAL_A_ROWS = {
    0: [2.1494925022125244e-6, 2.421438694000244e-7, 2.421438694000244e-7, 2.421438694000244e-7,
        2.421438694000244e-7, -9.527429938316345e-7],
    1: [1.9138678908348083e-6, 1.9138678908348083e-6, 1.9138678908348083e-6, 1.9138678908348083e-6,
        -3.0957162380218506e-6],
    2: [6.51925802230835e-9, 6.51925802230835e-9, 6.51925802230835e-9, -1.1883676052093506e-6],
    3: [6.51925802230835e-9, 6.51925802230835e-9, -1.1883676052093506e-6],
    4: [6.51925802230835e-9, -1.1883676052093506e-6],
    5: [-1.1883676052093506e-6],
}


def subnormal_mass():
    n = 7
    a = [[0.0] * n for _ in range(n)]
    for i in range(n):
        a[i][i] = SUBNORMAL_A_DIAGONAL[i]
        for k, v in enumerate(SUBNORMAL_A_ROWS.get(i, [])):
            a[i][i + 1 + k] = v
            a[i + 1 + k][i] = v
    return a


def spectrum(a, entries):
    """The finite ω² ascending, then one infinity per massless coordinate. A zero row of A (a
    massless coordinate) is condensed out exactly: S = B11 − B10 B00⁻¹ B01 over the others."""
    n = len(a)
    bm = mp.matrix(n, n)
    for i, j, v in entries:
        bm[i, j] = mp.mpf(v)
        bm[j, i] = mp.mpf(v)
    massless = [i for i in range(n) if all(x == 0.0 for x in a[i])]
    kept = [i for i in range(n) if i not in massless]
    am = mp.matrix([[mp.mpf(a[i][j]) for j in kept] for i in kept])
    stiffness = mp.matrix([[bm[i, j] for j in kept] for i in kept])
    if massless:
        b00 = mp.matrix([[bm[i, j] for j in massless] for i in massless])
        b10 = mp.matrix([[bm[i, j] for j in massless] for i in kept])
        stiffness = stiffness - b10 * mp.inverse(b00) * b10.T
    li = mp.inverse(mp.cholesky(am))
    m = li * stiffness * li.T
    m = (m + m.T) / 2
    return sorted(mp.eigsy(m, eigvals_only=True)) + [mp.inf] * len(massless)


def main():
    for name, (a, entries) in PENCILS.items():
        if isinstance(a, str):
            a = subnormal_mass()
        print(f"# {name}")
        for w in spectrum(a, entries):
            if mp.isinf(w):
                print("(f64::INFINITY, 0.0),")
                continue
            hi = float(w)
            lo = float(w - mp.mpf(hi))
            print(f"({hi!r}, {lo!r}),")


if __name__ == "__main__":
    main()
