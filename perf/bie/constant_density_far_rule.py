#!/usr/bin/env python3
"""Does the far rule's error on a CONSTANT double-layer density fall with h? (perf/RESULTS.md §1.6)

If D̃[1]'s far part came from an identity (the polyhedral corner tensor minus exact integrals over
the near elements) instead of the far rule itself, the operator would carry the far rule's error on
the constant density times u_i. For random nodes x_i of the unit icosphere this prints
max |far-rule sum − accurate integral| of (1/8π) T(x_i − y)·n over the flat elements beyond the
touching ones and one ring: edge-midpoint rule (the far field's) against 64 sub-triangles × the
7-point rule per element. Independent of the C++ code (numpy only).
    /usr/bin/python3 perf/bie/constant_density_far_rule.py LEVEL [NODES]
"""
import numpy as np, sys
def icosphere(level):
    t=(1+5**0.5)/2
    V=np.array([[-1,t,0],[1,t,0],[-1,-t,0],[1,-t,0],[0,-1,t],[0,1,t],[0,-1,-t],[0,1,-t],[t,0,-1],[t,0,1],[-t,0,-1],[-t,0,1]],float)
    F=[[0,11,5],[0,5,1],[0,1,7],[0,7,10],[0,10,11],[1,5,9],[5,11,4],[11,10,2],[10,7,6],[7,1,8],[3,9,4],[3,4,2],[3,2,6],[3,6,8],[3,8,9],[4,9,5],[2,4,11],[6,2,10],[8,6,7],[9,8,1]]
    V=[v/np.linalg.norm(v) for v in V]; F=[tuple(f) for f in F]
    for _ in range(level):
        cache={}; NF=[]
        def mid(a,b):
            k=(min(a,b),max(a,b))
            if k not in cache:
                m=(V[a]+V[b]); V.append(m/np.linalg.norm(m)); cache[k]=len(V)-1
            return cache[k]
        for a,b,c in F:
            ab,bc,ca=mid(a,b),mid(b,c),mid(c,a); NF+= [(a,ab,ca),(b,bc,ab),(c,ca,bc),(ab,bc,ca)]
        F=NF
    return np.array(V),np.array(F)
def Tn(x,y,n,w):  # sum over points y (N,3) with normals n (N,3) (unit) and weights w
    r=x-y; d=np.linalg.norm(r,axis=1); rn=(r*n).sum(1)
    c=-6*rn/d**5*w/(8*np.pi)
    return (r.T*c)@r
# 7-point Dunavant (degree 5)
a1,b1=0.0597158717897698,0.4701420641051151; a2,b2=0.7974269853530873,0.1012865073234563
bary=np.array([[1/3,1/3,1/3],[a1,b1,b1],[b1,a1,b1],[b1,b1,a1],[a2,b2,b2],[b2,a2,b2],[b2,b2,a2]])
wts=np.array([0.225]+[0.1323941527885062]*3+[0.1259391805448271]*3)
def subdiv_pts(P,k):  # P (3,3) triangle vertices -> points and weights (area-weighted) of k-level subdivision x 7 pts
    tris=[P]
    for _ in range(k):
        nt=[]
        for A,B,C in tris:
            ab,bc,ca=(A+B)/2,(B+C)/2,(C+A)/2; nt+=[(A,ab,ca),(B,bc,ab),(C,ca,bc),(ab,bc,ca)]
        tris=nt
    T=np.array(tris)  # (m,3,3)
    area=0.5*np.linalg.norm(np.cross(T[:,1]-T[:,0],T[:,2]-T[:,0]),axis=1)
    pts=np.einsum('qk,mkd->mqd',bary,T).reshape(-1,3); w=(area[:,None]*wts[None,:]).reshape(-1)
    return pts,w
level=int(sys.argv[1]); nsample=int(sys.argv[2]) if len(sys.argv)>2 else 20
V,F=icosphere(level)
rng=np.random.default_rng(1); sample=rng.choice(len(V),nsample,replace=False)
# element normals (flat facets, outward)
N=np.cross(V[F[:,1]]-V[F[:,0]],V[F[:,2]]-V[F[:,0]]); A=0.5*np.linalg.norm(N,axis=1); N/=2*A[:,None]
N*=np.sign((N*V[F].mean(1)).sum(1))[:,None]
# accurate points per element (3 subdivisions: 64 sub-triangles x 7 points)
acc=[subdiv_pts(V[f],3) for f in F]
worst=0
for i in sample:
    touch=set(np.where((F==i).any(1))[0]); ringv=set(F[list(touch)].ravel())
    near=set(np.where(np.isin(F,list(ringv)).any(1))[0])  # touching + 1 ring (elements sharing a vertex with the touching ones)
    far=np.array(sorted(set(range(len(F)))-near))
    # edge-midpoint rule
    P=V[F[far]]; mids=np.concatenate([(P[:,0]+P[:,1])/2,(P[:,1]+P[:,2])/2,(P[:,2]+P[:,0])/2]); nn=np.concatenate([N[far]]*3); ww=np.concatenate([A[far]/3]*3)
    rule=Tn(V[i],mids,nn,ww)
    ys=np.concatenate([acc[e][0] for e in far]); ws=np.concatenate([acc[e][1] for e in far]); ns=np.repeat(N[far],len(acc[0][1]),axis=0)
    exact=Tn(V[i],ys,ns,ws)
    worst=max(worst,np.abs(rule-exact).max())
h=np.sqrt(4*np.pi/len(F)*4/np.sqrt(3))
print(f"level {level} elements {len(F)} h {h:.4f} max |far rule - accurate| over {nsample} nodes: {worst:.3e}")
