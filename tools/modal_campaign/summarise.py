"""Summarise OUTDIR/results.jsonl written by run.py as a Markdown table, per family and
option: cases, modes checked, violations by kind (bound, zero, sign, infinite, nonfinite,
panic), refusals, worst |error|/bound among the modes within their bound, modes reported
undecided and modes reported zero (correctly: within 100x their resolution), and Sturm
self-checks reported inconsistent; then every violation.

Usage:  python3 summarise.py OUTDIR [path/to/mechanica] > results.md
(with the binary, `mechanica version` and the date head the output).
"""
import collections
import datetime
import json
import os
import subprocess
import sys

KINDS = ['bound', 'zero', 'sign', 'infinite', 'nonfinite', 'panic', 'timeout', 'badjson', 'no_modes']


def main():
    out = sys.argv[1]
    recs = [json.loads(l) for l in open(os.path.join(out, 'results.jsonl'))]
    if len(sys.argv) > 2:
        v = subprocess.run([sys.argv[2], 'version'], capture_output=True, text=True).stdout.strip()
        print(f'# `mechanica modes` hostile-pencil campaign\n\n{datetime.date.today().isoformat()}\n')
        print('```\n' + v + '\n```\n')
        print('Reproduce: `python3 tools/modal_campaign/run.py target/release/mechanica OUT && '
              'python3 tools/modal_campaign/summarise.py OUT target/release/mechanica`. '
              'Exact values: 60-digit mpmath eigenvalues of the stored pencils; "zero" counts a '
              'mode called zero whose exact value exceeds 100x its first-order data resolution; '
              '"infinite" a wrong number of infinite (massless) modes; "zero (correct)" the zero '
              'claims within that resolution.\n')
    agg = collections.OrderedDict()
    viol = []
    for r in recs:
        a = agg.setdefault((r['fam'], r['opt']), dict(cases=0, modes=0, worst=0.0, und=0, zero=0,
                                                     refused=0, sturm=0, c=collections.Counter()))
        a['cases'] += 1; a['modes'] += sum(r['kinds'].values())
        a['und'] += r['kinds'].get('undecided', 0); a['zero'] += r['kinds'].get('zero', 0)
        a['worst'] = max([a['worst']] + r['ratios'])
        for kind, info in r['flags']:
            a['zero'] -= kind == 'zero'
            if kind == 'refused':
                a['refused'] += 1
            elif kind == 'sturm_inconsistent':
                a['sturm'] += 1
            else:
                a['c'][kind] += 1; viol.append((r, kind, info))
    print('| family | option | cases | modes checked | ' + ' | '.join(KINDS[:6]) +
          ' | refused | worst err/bound | undecided | zero (correct) | Sturm inconsistent |')
    print('|' + '---|' * 15)
    for (fam, opt), a in agg.items():
        print(f"| {fam} | {opt} | {a['cases']} | {a['modes']} | " +
              ' | '.join(str(a['c'][k]) for k in KINDS[:6]) +
              f" | {a['refused']} | {a['worst']:{'.4g' if a['worst'] < 0.999 else '.7f'}} | {a['und']} | {a['zero']} | {a['sturm']} |")
    other = sum(a['c'][k] for a in agg.values() for k in KINDS[6:])
    print(f'\nTimeouts / unreadable reports: {other}. Violations: {len(viol)}.\n')
    for r, kind, info in viol:
        print(f"- {kind}: {r['fam']}-{r['seed']} ({r['sub']}, n={r['n']}) `{r['opt']}`: {json.dumps(info)}")


if __name__ == '__main__':
    main()
