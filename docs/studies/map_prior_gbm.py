"""Map-prior features on top of gradient-boosted trees, T-Drive. A study, not part of the library.

The trees forecast each step's displacement from the last position in the frame aligned
with the last heading (the features: last speed, mean interval, the last 8 legs' aligned
velocities and durations, speed statistics, the window's mean aligned velocity; 200 rounds,
learning rate 0.1, 31 leaves, targets clipped at their 0.95 quantile), as `aligned-gbm` does
on T-Drive. "prior" adds 11 features: the median future displacement (5 steps, along and
across) of the training origins within RAD m, heading within 30 degrees, speed within
0.5-2x (moving faster than 1 m/s, at least 3, other taxis only, at most 50), read at this
origin's future times, and their count. Splits by taxi, seeded: NF=5 trains on four folds
and tests on the fifth; NF=3 THIRD=1 trains on one third and tests on the rest (each
window's forecast comes from the last third that left it out). Needs numpy, scipy,
lightgbm.

    RAD=200 NF=5 python docs/studies/map_prior_gbm.py ../shared/data/tdrive
    RAD=200 NF=3 THIRD=1 python docs/studies/map_prior_gbm.py ../shared/data/tdrive
"""
import sys
import numpy as np, os, glob, time, lightgbm as lgb
from scipy.spatial import cKDTree
root=sys.argv[1]+"/taxi_log_2008_by_id"
LAT0,LON0,R=39.95,116.4,6371008.8
kx,ky=np.deg2rad(1)*R*np.cos(np.deg2rad(LAT0)),np.deg2rad(1)*R
segs=[]
for f in sorted(glob.glob(root+"/*.txt")):
    rows=[l.split(",") for l in open(f).read().split("\n") if l]
    if len(rows)<25: continue
    t=np.array([np.datetime64(r[1].replace(" ","T"),"s").astype(np.int64) for r in rows],float)
    lon=np.array([float(r[2]) for r in rows]); lat=np.array([float(r[3]) for r in rows])
    ok=(lon>=115.4)&(lon<=117.6)&(lat>=39.4)&(lat<=41.1); o=np.argsort(t[ok],kind="stable")
    t,lon,lat=t[ok][o],lon[ok][o],lat[ok][o]
    keep=np.concatenate([[True],np.diff(t)>0])[:len(t)]; t,lon,lat=t[keep],lon[keep],lat[keep]
    x,y=(lon-LON0)*kx,(lat-LAT0)*ky; tid=int(os.path.basename(f)[:-4])
    for s in np.split(np.arange(len(t)),np.where(np.diff(t)>300)[0]+1):
        if len(s)>=25: segs.append((tid,t[s],x[s],y[s]))
# windows
W=[];G=[];SEG=[];IDX=[]
for si,(tid,t,x,y) in enumerate(segs):
    for i in range(19,len(t)-5):
        W.append(np.stack([t[i-19:i+6]-t[i],x[i-19:i+6]-x[i],y[i-19:i+6]-y[i]],1)); G.append(tid); SEG.append(si); IDX.append(i)
W=np.array(W); G=np.array(G); SEG=np.array(SEG); IDX=np.array(IDX)
T,Xp,Yp=W[:,:,0],W[:,:,1],W[:,:,2]; o=19
def legvel(j):
    dt=T[:,o-j]-T[:,o-j-1]; return (Xp[:,o-j]-Xp[:,o-j-1])/dt,(Yp[:,o-j]-Yp[:,o-j-1])/dt,dt
legs=[legvel(j) for j in range(19)]
c=np.ones(len(W)); s=np.zeros(len(W)); done=np.zeros(len(W),bool)
for j in range(8):
    a,b,_=legs[j]; sp=np.hypot(a,b); m=(~done)&(sp>1e-9); c[m]=a[m]/sp[m]; s[m]=b[m]/sp[m]; done|=m
rot=lambda a,b:(c*a+s*b,c*b-s*a)
F=[np.hypot(*rot(legs[0][0],legs[0][1])),(T[:,o]-T[:,0])/19]
for j in range(8):
    ra,rb=rot(legs[j][0],legs[j][1]); F+=[ra,rb,legs[j][2]]
sps=np.array([np.hypot(l[0],l[1]) for l in legs])
F+=[sps.std(0),sps.max(0),np.median(sps,0),(sps<0.3).sum(0)]
F+=list(rot((Xp[:,o]-Xp[:,0])/(T[:,o]-T[:,0]),(Yp[:,o]-Yp[:,0])/(T[:,o]-T[:,0])))
X0=np.column_stack(F)
# absolute origin position, velocity (world), heading
ox=np.array([segs[a][2][b] for a,b in zip(SEG,IDX)]); oy=np.array([segs[a][3][b] for a,b in zip(SEG,IDX)])
v0x,v0y=legs[0][0],legs[0][1]; s0=np.hypot(v0x,v0y); h0=np.arctan2(v0y,v0x)
tau=T[:,o+1:o+6]
NF=int(os.environ.get('NF','5')); THIRD=os.environ.get('THIRD')=='1'
rng=np.random.default_rng(0); ug=np.unique(G); perm=rng.permutation(ug); fmap=dict(zip(perm,np.arange(len(perm))%NF)); fold=np.array([fmap[g] for g in G])
RAD=float(os.environ.get("RAD","200"))
def prior(train_mask, query_idx):
    # neighbours among training windows' origins (moving), exclude same taxi
    tr=np.where(train_mask & (s0>1.0))[0]
    tree=cKDTree(np.c_[ox[tr],oy[tr]])
    out=np.full((len(query_idx),11),np.nan); 
    for qi,w in enumerate(query_idx):
        if s0[w]<=1.0: continue
        nb=tr[tree.query_ball_point([ox[w],oy[w]],RAD)]
        nb=nb[(G[nb]!=G[w])]
        if len(nb)==0: continue
        d=np.abs((h0[nb]-h0[w]+np.pi)%(2*np.pi)-np.pi); sr=s0[nb]/s0[w]
        nb=nb[(d<=np.deg2rad(30))&(sr>=0.5)&(sr<=2)]
        if len(nb)<3: continue
        # neighbour futures at the query's tau, interpolated along its own segment, rotated into the query's aligned frame
        fx=[];fy=[]
        for n in nb[:50]:
            _,t,x,y=segs[SEG[n]]; i=IDX[n]; at=t[i]+tau[w]
            ax=np.interp(at,t,x)-x[i]; ay=np.interp(at,t,y)-y[i]
            fx.append(ax); fy.append(ay)
        fx=np.median(fx,0); fy=np.median(fy,0)
        pa=c[w]*fx+s[w]*fy; pb=c[w]*fy-s[w]*fx
        out[qi,:5]=pa; out[qi,5:10]=pb; out[qi,10]=len(nb)
    return out
t0=time.time()
# features: for test windows of fold f, from training taxis of fold f; for training windows (used when f is a test fold elsewhere) the same rule applies per fold
PF={}
for f in range(NF):
    trm=(fold==f) if THIRD else (fold!=f)
    PF[f]=(prior(trm,np.where(~trm)[0]), prior(trm,np.where(trm)[0]))
    print("prior fold",f,"%.0f s"%(time.time()-t0),flush=True)
prm=dict(objective="l2",learning_rate=0.1,num_leaves=31,min_child_samples=100,verbose=-1,num_threads=2,lambda_l2=1.0)
for name in ["base","prior"]:
    tot=[]; 
    for k in range(1,6):
        ya,yb=rot(Xp[:,o+k],Yp[:,o+k]); pa=np.zeros(len(W)); pb=np.zeros(len(W))
        for f in range(NF):
            tr=(fold==f) if THIRD else (fold!=f); te=~tr
            Xtr,Xte=X0[tr],X0[te]
            if name=="prior":
                Xte=np.c_[Xte,PF[f][0]]; Xtr=np.c_[Xtr,PF[f][1]]
            for yv,out in ((ya,pa),(yb,pb)):  # (one model per step and axis)
                cq=np.quantile(np.abs(yv[tr]),0.95)
                m=lgb.train(prm,lgb.Dataset(Xtr,np.clip(yv[tr],-cq,cq)),200); out[te]=m.predict(Xte)
        tot.append(np.hypot(ya-pa,yb-pb))
    tot=np.array(tot)
    print(name, "mean %.2f" % tot.mean(), "steps", tot.mean(1).round(1), flush=True)
