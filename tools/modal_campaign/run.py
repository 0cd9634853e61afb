"""Run `mechanica --json modes` on the generated pencils and judge every reported mode
against a 60-digit mpmath reference of the stored (double) matrices.

Usage:   pip install mpmath numpy
         python3 run.py path/to/mechanica OUTDIR [--families fe,dense] [--seeds 0:40]
                        [--options default,always,off,values_only,lowest5]
Writes OUTDIR/cases/<family>-<seed>/{A.mtx,B.mtx,ref.json} (reference cached) and appends
one JSON line per (case, option) to OUTDIR/results.jsonl; summarise with summarise.py.

Per mode, with w the exact omega^2, r its first-order data resolution
u (|x|'|B||x| + |w| |x|'|A||x|) / x'Ax (u = 2^-53, x the exact eigenvector), the checks are:
  bound       |reported - w| > reported bound
  zero        kind "zero" while |w| > 100 r
  sign        kind "oscillatory" with w <= 0, "unstable" with w >= 0, "infinite" with a
              finite omega_sq or a null omega_sq with another kind
  infinite    number of infinite (omega_sq null) modes differs from the exact count
              (massless directions; with --lowest 5, fewer or more than min(5, finite) modes)
  nonfinite   NaN or infinity anywhere in the report
  panic       exit code 101, a signal, or "panicked" on stderr
Also recorded: undecided modes, refusals (nonzero exit with a message), Sturm self-checks
reported inconsistent, and |error|/bound for every mode within its bound.
"""
import argparse
import json
import os
import subprocess
import sys
import time

import mpmath as mp
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen import FAMILIES, read_mtx, write_mtx  # noqa: E402

OPTIONS = {'default': [], 'always': ['--refinement', 'always'], 'off': ['--refinement', 'off'],
           'values_only': ['--values-only'], 'lowest5': ['--lowest', '5']}
# seeds 0..39 (0..69 / 0..79 for the two families with six / three sub-kinds) and 100..139
SEEDS = {f: list(range(40)) + list(range(100, 140)) for f in FAMILIES}
SEEDS['semidef_repeated'] = list(range(70)) + list(range(100, 140))
SEEDS['indefinite'] = list(range(80)) + list(range(100, 140))
ENV = dict(os.environ, OPENBLAS_NUM_THREADS='1', OMP_NUM_THREADS='1', RAYON_NUM_THREADS='1')
DPS = 60


def reference(A, B):
    """Exact finite eigenvalues (ascending) with their resolutions, and the number of
    infinite ones. Massless coordinates (zero rows of A) are condensed out of B; if the
    remaining A is singular the roles are reversed (needs the condensed B definite)."""
    mp.mp.dps = DPS
    n = A.shape[0]
    zero = [i for i in range(n) if not np.any(A[i])]
    m = [i for i in range(n) if i not in set(zero)]
    M = lambda X, r, c: mp.matrix([[mp.mpf(float(X[i, j])) for j in c] for i in r])
    Am = M(A, m, m); S = M(B, m, m); G = None
    if zero:
        G = mp.inverse(M(B, zero, zero)) * M(B, zero, m)
        S = S - M(B, m, zero) * G
    tiny = mp.mpf(10) ** (-DPS + 15)
    try:
        L = mp.cholesky(Am)
        if min(L[i, i] ** 2 / Am[i, i] for i in range(len(m))) < tiny:
            raise ValueError('A singular to working precision')
        Li = mp.inverse(L); C = Li * S * Li.T
        E, Q = mp.eigsy((C + C.T) / 2)
        pairs = [(E[k], Li.T * Q[:, k]) for k in range(len(m))]
    except (ValueError, ZeroDivisionError):
        LS = mp.inverse(mp.cholesky(S)); C = LS * Am * LS.T
        mu, Q = mp.eigsy((C + C.T) / 2)
        big = max(abs(v) for v in mu)
        pairs = [(1 / mu[k], LS.T * Q[:, k]) for k in range(len(m)) if abs(mu[k]) > big * tiny]
    scale = max([abs(e) for e, _ in pairs] + [mp.mpf(0)])
    out = []
    for e, xm in sorted(pairs, key=lambda p: p[0]):
        x = mp.matrix(n, 1)
        for a, i in enumerate(m): x[i] = xm[a]
        if zero:
            x0 = -(G * xm)
            for a, i in enumerate(zero): x[i] = x0[a]
        xa = np.array([abs(float(v)) for v in x])
        num = xa @ np.abs(B) @ xa + abs(float(e)) * (xa @ np.abs(A) @ xa)
        res = 2.0 ** -53 * num / float((xm.T * Am * xm)[0])
        if abs(e) <= scale * mp.mpf(10) ** (-DPS + 12):
            e = mp.mpf(0)   # exact zero eigenvalue (e.g. a free structure), up to mpmath noise
        out.append((mp.nstr(e, 40), res))
    return out, n - len(out)


def _check_finite(obj):
    if isinstance(obj, float):
        return obj == obj and abs(obj) != float('inf')
    if isinstance(obj, dict):
        return all(_check_finite(v) for v in obj.values())
    if isinstance(obj, list):
        return all(_check_finite(v) for v in obj)
    return True


def judge(rep, ref, nz, n, opt):
    flags, ratios, kinds = [], [], {}
    steps = {s['analysis']: s for s in rep.get('steps', [])}
    pm = steps.get('pencil_modes')
    if pm is None:
        return [('no_modes', '')], ratios, kinds
    modes = pm['modes']
    fin = [md for md in modes if md['omega_sq'] is not None]
    inf = [md for md in modes if md['omega_sq'] is None]
    if opt == 'lowest5':
        exp = ref[:5]
        if len(modes) != min(5, len(ref)):
            flags.append(('infinite', f'{len(modes)} modes reported, exact finite {len(ref)}'))
    else:
        exp = ref
        if len(fin) != n - nz or len(inf) != nz:
            flags.append(('infinite', f'{len(fin)} finite, {len(inf)} infinite; exact {n - nz}, {nz}'))
    for md in inf:
        if md['kind'] != 'infinite':
            flags.append(('sign', f'omega_sq null with kind {md["kind"]}'))
    for r, md in enumerate(sorted(fin, key=lambda md: md['omega_sq'])[:len(exp)]):
        e = mp.mpf(exp[r][0]); res = exp[r][1]
        w, b, k = md['omega_sq'], md['bound'], md['kind']
        kinds[k] = kinds.get(k, 0) + 1
        info = dict(mode=r, kind=k, omega_sq=w, bound=b, exact=exp[r][0][:26], resolution=res)
        err = abs(mp.mpf(w) - e)
        if b is None:
            flags.append(('bound', dict(info, why='no bound')))
        else:
            ratio = float(err / b) if b > 0 else (0.0 if err == 0 else float('inf'))
            if ratio > 1:
                flags.append(('bound', dict(info, ratio=ratio)))
            else:
                ratios.append(ratio)
        if (k == 'oscillatory' and e <= 0) or (k == 'unstable' and e >= 0) or k == 'infinite':
            flags.append(('sign', info))
        elif k == 'zero' and abs(float(e)) > 100 * res:
            flags.append(('zero', dict(info, exact_over_res=abs(float(e)) / res)))
    sc = steps.get('sturm_check')
    if sc and sc.get('status') == 'inconsistent':
        flags.append(('sturm_inconsistent', json.dumps(sc)))
    return flags, ratios, kinds


def run_case(binary, out, fam, seed, opts, log):
    A, B, meta = FAMILIES[fam](seed)
    d = os.path.join(out, 'cases', f'{fam}-{seed}')
    os.makedirs(d, exist_ok=True)
    write_mtx(f'{d}/A.mtx', A); write_mtx(f'{d}/B.mtx', B)
    assert np.array_equal(read_mtx(f'{d}/A.mtx'), A) and np.array_equal(read_mtx(f'{d}/B.mtx'), B)
    rpath = f'{d}/ref.json'
    if os.path.exists(rpath):
        ref, nz = json.load(open(rpath))
    else:
        ref, nz = reference(A, B)
        json.dump([ref, nz], open(rpath, 'w'))
    n = A.shape[0]
    for opt in opts:
        cmd = [binary, '--json', 'modes', '--mass', f'{d}/A.mtx', '--stiffness', f'{d}/B.mtx'] + OPTIONS[opt]
        rec = dict(fam=fam, seed=seed, n=n, sub=meta['sub'], opt=opt, cmd=' '.join(cmd),
                   flags=[], ratios=[], kinds={})
        t = time.time()
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=ENV)
        except subprocess.TimeoutExpired:
            p = None; rec['flags'] = [('timeout', '')]
        rec['time'] = time.time() - t
        if p is not None and (p.returncode == 101 or p.returncode < 0 or 'panicked' in p.stderr):
            rec['flags'] = [('panic', f'rc={p.returncode} {p.stderr.strip()[-400:]}')]
        elif p is not None and p.returncode != 0:
            rec['flags'] = [('refused', f'rc={p.returncode} {p.stderr.strip()[-300:]}')]
        elif p is not None:
            try:
                rep = json.loads(p.stdout)
            except ValueError:
                rep = None; rec['flags'] = [('badjson', p.stdout[:300])]
            if rep is not None:
                flg, rat, kinds = judge(rep, ref, nz, n, opt)
                if not _check_finite(rep):
                    flg.append(('nonfinite', ''))
                rec.update(flags=flg, ratios=rat, kinds=kinds)
        log.write(json.dumps(rec) + '\n'); log.flush()
        bad = [i for i in rec['flags'] if i[0] not in ('refused', 'sturm_inconsistent')]
        if bad:
            print(fam, seed, meta['sub'], opt, bad[:2], flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('binary'); ap.add_argument('out')
    ap.add_argument('--families', default=','.join(FAMILIES))
    ap.add_argument('--seeds', help='a:b, for every chosen family (default: SEEDS)')
    ap.add_argument('--options', default=','.join(OPTIONS))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    opts = a.options.split(',')
    with open(os.path.join(a.out, 'results.jsonl'), 'a') as log:
        for fam in a.families.split(','):
            seeds = range(*map(int, a.seeds.split(':'))) if a.seeds else SEEDS[fam]
            for seed in seeds:
                run_case(a.binary, a.out, fam, seed, opts, log)
            print('done', fam, flush=True)


if __name__ == '__main__':
    main()
