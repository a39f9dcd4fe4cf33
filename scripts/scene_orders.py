#!/usr/bin/env python3
# scene_orders.py — Moreau–Jean's observed order in umax on scenes against
# the exact row reference (docs/scenes.md §5): the five example scenes and
# nine random rows of 2-5 SDOFs (seed 19), dt = 4e-3 ... 2.5e-4 s halving;
# the least-squares slope of log err_umax on log dt and the step-to-step
# orders.  Usage: python3 scripts/scene_orders.py [path/to/pound]
import json, subprocess, math, random, os, sys, tempfile
P=sys.argv[1] if len(sys.argv) > 1 else "build/pound"
def conv(args):
    out=subprocess.run([P,'converge']+args+['--dt','4e-3:2.5e-4:5','--error','umax','--json'],capture_output=True,text=True)
    if out.returncode: return None, out.stderr.strip()
    rows=json.loads(out.stdout)['rows']
    dts=[r['dt'] for r in rows]; es=[r['err_umax_rel'] for r in rows]
    return dts, es
def fit(dts,es):
    xs=[math.log(d) for d in dts]; ys=[math.log(max(e,1e-16)) for e in es]
    mx=sum(xs)/len(xs); my=sum(ys)/len(ys)
    return sum((x-mx)*(y-my) for x,y in zip(xs,ys))/sum((x-mx)**2 for x in xs)
tmp=tempfile.mkdtemp()
cases=[]
for f in ['two-sdof','three-buildings','bridge-10span','three-sdof','oscillator']:
    cases.append((f,['--scene','examples/scenes/%s.json'%f]))
rng=random.Random(19)
for k in range(9):
    n=rng.randint(2,5)
    sts=[{'name':'S%d'%i,'T0':round(rng.uniform(0.3,2.0),3)} for i in range(n)]
    cts=[{'a':'S%d'%i,'b':'S%d'%(i+1),'gap':round(rng.uniform(0.005,0.03),4),'eps':round(rng.uniform(0.3,0.9),2)} for i in range(n-1)]
    if rng.random()<0.5: cts.append({'a':'wall','b':'S0','gap':round(rng.uniform(0.005,0.03),4),'eps':0.6})
    sc={'excitation':{'pulse':rng.choice(['sine','cosine']),'ap':round(rng.uniform(2,6),2),'Tp':round(rng.uniform(0.3,1.0),2),'dir':rng.choice(['+x','-x'])},'structures':sts,'contacts':cts,'tend':3.0}
    fn=os.path.join(tmp,'r%d.json'%k); json.dump(sc,open(fn,'w')); cases.append((fn,['--scene',fn]))
for name,args in cases:
    d,e=conv(args)
    if d is None: print(name,'ERR',e); continue
    steps=[math.log(e[i-1]/e[i])/math.log(d[i-1]/d[i]) if e[i]>0 and e[i-1]>0 else float('nan') for i in range(1,len(e))]
    print('%-16s slope %.2f  steps %s  errs %s'%(os.path.basename(name),fit(d,e),' '.join('%.2f'%s for s in steps),' '.join('%.2g'%x for x in e)),flush=True)
