#!/usr/bin/env python3
"""Parse log.measure_<tag>_r<rep> + contacts_<tag>_r<rep>.txt -> CSV rows (one per run) + summary on stderr."""
import glob, re, sys, statistics as st
rows = []
for log in sorted(glob.glob('log.measure_*_r*')):
    m = re.match(r'log\.measure_(.+)_r(\d+)$', log)
    tag, rep = m.group(1), int(m.group(2))
    txt = open(log).read()
    lm = re.search(r'Loop time of ([\d.eE+-]+) on \d+ procs for (\d+) steps with (\d+) atoms', txt)
    if not lm or int(lm.group(2)) == 0: continue
    loop, steps, nat = float(lm.group(1)), int(lm.group(2)), int(lm.group(3))
    seg = txt[lm.end():]
    def g(name):
        mm = re.search(name + r'\s+time \(%\) = ([\d.eE+-]+)', seg)
        return float(mm.group(1)) if mm else float('nan')
    pair, neigh, modify = g('Pair'), g('Neigh'), g('Modfy')
    walls = sum(float(x) for x in re.findall(r'Fix \w+ wall/gran time \(%\) = ([\d.eE+-]+)', seg.split('Loop time')[0]))
    integ = re.search(r'Fix integr \S+ time \(%\) = ([\d.eE+-]+)', seg)
    integ = float(integ.group(1)) if integ else float('nan')
    nb = re.search(r'Neighbor list builds = (\d+)', seg); nb = int(nb.group(1)) if nb else -1
    an = re.search(r'Ave neighs/atom = ([\d.eE+-]+)', seg); an = float(an.group(1)) if an else float('nan')
    try:
        c = open(f'contacts_{tag}_r{rep}.txt').read().split('\n')
        npairs = int(c[c.index('ITEM: NUMBER OF ENTRIES') + 1])
    except Exception:
        npairs = -1
    scene = 'drum' if tag.startswith('drum_') else 'box'
    # process CPU (user+sys) minus the zero-step run of the same tag (if recorded)
    def cpu(fn):
        try: u, s_, e = open(fn).read().split()[-3:]; return float(u) + float(s_)
        except Exception: return float('nan')
    cpu_ns = (cpu(f'cputime_{tag}_r{rep}.txt') - cpu(f'cputime_{tag}_r0.txt')) / (steps * nat) * 1e9
    if tag.startswith('drum_'):   # drum: in-process /proc stamps around each timed run (cpustamp.sh)
        try:
            st_ = {l.split()[0]: l.split()[1:] for l in open(f'cpustamp_{tag}.txt')}
            t0, t1 = st_[f'start{rep}'], st_[f'end{rep}']
            cpu_ns = ((int(t1[0]) + int(t1[1])) - (int(t0[0]) + int(t0[1]))) / float(t0[2]) / (steps * nat) * 1e9
        except Exception:
            cpu_ns = float('nan')
    rows.append(dict(scene=scene, shape=tag[5:] if scene == 'drum' else tag, rep=rep, natoms=nat, steps=steps, loop_s=loop,
                     ns_per_particle_step=loop / (steps * nat) * 1e9, cpu_ns_per_particle_step=cpu_ns,
                     pair_share=pair / loop, neigh_share=neigh / loop, modify_share=modify / loop,
                     walls_share=walls / loop, integrator_share=integ / loop,
                     neigh_builds=nb, neighs_per_atom=an, pp_contacts=npairs,
                     contacts_per_particle=2 * npairs / nat if npairs >= 0 else float('nan')))
keys = list(rows[0].keys())
print(','.join(keys))
for r in rows:
    print(','.join(f'{r[k]:.4g}' if isinstance(r[k], float) else str(r[k]) for k in keys))
# summary (stderr): per scene and shape; ratio against the sphere of the same scene and same binary
import math
print('\nscene,shape,median_ns,min_ns,max_ns,ratio_to_sphere(median),pair_share,modify_share,contacts_per_particle,nruns,cpu_ns(median [min-max]) ratio', file=sys.stderr)
groups = []
for r in rows:
    if (r['scene'], r['shape']) not in groups: groups.append((r['scene'], r['shape']))
for sc, sh in sorted(groups, key=lambda g: (g[0], ['sphere','sphere_debbin','sq22','ell2','cube8'].index(g[1]) if g[1] in ['sphere','sphere_debbin','sq22','ell2','cube8'] else 9)):
    R = [r for r in rows if r['scene'] == sc and r['shape'] == sh]
    v = [r['ns_per_particle_step'] for r in R]
    ref = [r['ns_per_particle_step'] for r in rows if r['scene'] == sc and r['shape'] == 'sphere']
    ratio = st.median(v) / st.median(ref) if ref else float('nan')
    cv = [r['cpu_ns_per_particle_step'] for r in R if not math.isnan(r['cpu_ns_per_particle_step'])]
    cref = [r['cpu_ns_per_particle_step'] for r in rows if r['scene'] == sc and r['shape'] == 'sphere' and not math.isnan(r['cpu_ns_per_particle_step'])]
    cpu_s = f"{st.median(cv):.0f} [{min(cv):.0f}-{max(cv):.0f}] ratio {st.median(cv)/st.median(cref):.2f}" if cv and cref else 'n/a'
    cpp = [r['contacts_per_particle'] for r in R if not math.isnan(r['contacts_per_particle'])]
    print(f"{sc},{sh},{st.median(v):.0f},{min(v):.0f},{max(v):.0f},{ratio:.2f},"
          f"{st.median([r['pair_share'] for r in R]):.3f},{st.median([r['modify_share'] for r in R]):.3f},"
          f"{(st.median(cpp) if cpp else float('nan')):.2f},{len(R)},{cpu_s}", file=sys.stderr)
