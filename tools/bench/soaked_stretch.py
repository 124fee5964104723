"""Longest stretch link of a soaked cloth landing on a sphere, frame by frame.

    PYTHONPATH=build/python .venv/bin/python tools/bench/soaked_stretch.py \
        INTEGRATOR STEPS WETNESS [FRAMES] [thick=0.02] [adhesion=..] [spread=..] [wet_friction=..]

A 2 m cloth (30 x 30) dropped from 1 m onto a 64 x 32 UV sphere of radius
0.5 m (collider thickness `thick`, friction 0.5), STEPS substeps per frame
(0: automatic). Prints every sixth frame, and stops at the first frame where
a link is longer than 1.5x its rest length; then the five longest links,
the distance of their ends from the centre and whether they are stuck.
"""
import sys
import time

import numpy as np
import wetcloth as wc  # noqa: E402
def sphere(seg, rings, R):
    v=[(0,0,R)]
    for j in range(1,rings):
        th=np.pi*j/rings
        for i in range(seg):
            ph=2*np.pi*i/seg; v.append((R*np.sin(th)*np.cos(ph),R*np.sin(th)*np.sin(ph),R*np.cos(th)))
    v.append((0,0,-R)); bot=len(v)-1
    t=[(0,1+i,1+(i+1)%seg) for i in range(seg)]
    for j in range(rings-2):
        for i in range(seg):
            a=1+j*seg+i; b=1+j*seg+(i+1)%seg; t+= [(a,a+seg,b),(b,a+seg,b+seg)]
    base=1+(rings-2)*seg
    t+=[(bot,base+(i+1)%seg,base+i) for i in range(seg)]
    return np.array(v),np.array(t)
integ=sys.argv[1]; steps=int(sys.argv[2]); wet=float(sys.argv[3]); frames=int(sys.argv[4]) if len(sys.argv)>4 else 36
kw=dict(kv.split('=') for kv in sys.argv[5:])
w=wc.World(integrator=integ, threads=1)
v,t=sphere(64,32,0.5)
w.add_mesh_collider(v,t,thickness=float(kw.get('thick',0.02)),friction=0.5)
m=wc.Material()
for k in ('adhesion','spread','wet_friction','wet_softening','wet_mass_gain'):
    if k in kw: setattr(m,k,float(kw[k]))
c=w.add_grid_cloth(30,30,size=(2,2),center=(0,0,1),wetness=wet, material=m)
links=None
t0=time.time()
for f in range(frames):
    w.advance(1/24, substeps=steps)
    p=c.positions
    if links is None:
        idx=np.arange(900).reshape(30,30); 
        pairs=np.concatenate([np.c_[idx[:,:-1].ravel(),idx[:,1:].ravel()],np.c_[idx[:-1].ravel(),idx[1:].ravel()]]); rest=2/29
    L=np.linalg.norm(p[pairs[:,0]]-p[pairs[:,1]],axis=1).max()/rest
    if f%6==5 or L>1.5: print(f, 'longest %.3f'%L, 'zmax %.3f'%p[:,2].max(), 'substeps', w.last_substeps if hasattr(w,'last_substeps') else '', flush=True)
    if L>1.5: break
print('time %.1f s'%(time.time()-t0), 'intersections', w.count_intersections())
p=c.positions
Ls=np.linalg.norm(p[pairs[:,0]]-p[pairs[:,1]],axis=1)/rest
k=np.argsort(Ls)[-5:]
st=c.stuck if hasattr(c,'stuck') else None
for kk in k:
    a,b=pairs[kk]; print('link',a,b,'%.3f'%Ls[kk],'r_a %.4f r_b %.4f'%(np.linalg.norm(p[a]),np.linalg.norm(p[b])),'stuck',None if st is None else (st[a],st[b]), 'z %.3f %.3f'%(p[a,2],p[b,2]))
print('stuck total', None if st is None else st.sum())
