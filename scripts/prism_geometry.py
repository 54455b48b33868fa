#!/usr/bin/env python3
"""Geometry of scenes/prism.ron and an independent prediction of where the light's images appear.

A 2-D (xz-plane) ray tracer in f64 with Snell's law and the N-SF11 Sellmeier
equation, written separately from the renderer: it places an equilateral prism
so that the camera's -z ray passes at minimum deviation for 589.3 nm, puts the
light on the exit ray, writes meshes/prism.obj, and prints the film column at
which each wavelength's image of the light must appear. tests/spectral.rs
checks the renderer against these columns. Run from the repository root.
"""
import math
B=[1.73759695,0.313747346,1.89878101];C=[0.013188707,0.0623068142,155.23629]
def n(l):
  l2=(l/1000)**2; return math.sqrt(1+sum(b*l2/(l2-c) for b,c in zip(B,C)))
A=math.radians(60)
n0=n(589.3)
D0=2*math.asin(n0*math.sin(A/2))-A
i0=(D0+A)/2
print("n589",n0,"D0 deg",math.degrees(D0),"i0",math.degrees(i0))
# 2D in xz-plane. incoming dir d=(0,-1) in (x,z). Face1 normal (outward) makes angle i0 with -d=(0,1).
# Rays bend toward base. Let the base be on the -x side?? choose: face1 outward normal = rotate (0,1) by +i0 (towards +x): n1=(sin i0, cos i0)
def rot(v,a): return (v[0]*math.cos(a)-v[1]*math.sin(a), v[0]*math.sin(a)+v[1]*math.cos(a))
n1=(math.sin(i0), math.cos(i0))
# face2 outward normal = n1 rotated by -(180-A)?? interior angle between faces at apex = A; outward normals differ by 180-A.
n2=rot(n1, -(math.pi - A))
print("n1",n1,"n2",n2)
# apex point where faces meet; put prism center at (0,-3). Build triangle: apex P, faces along directions perpendicular to normals.
# face1 line direction t1 perpendicular to n1; face2 t2 perpendicular to n2; apex is the common vertex; side length s
s=2.4
t1=(-n1[1], n1[0]); t2=(n2[1], -n2[0])
# choose orientation so both t go away from apex into the base side; check with base normal = -(n1+n2) normalized
nb=(-(n1[0]+n2[0]), -(n1[1]+n2[1])); L=math.hypot(*nb); nb=(nb[0]/L, nb[1]/L)
print("base normal", nb)
# apex is opposite the base: apex = centroid - nb*h*2/3
h=s*math.sqrt(3)/2
cx,cz=0.0,-3.0
apex=(cx-nb[0]*h*2/3, cz-nb[1]*h*2/3)
# base vertices: centroid + nb*h/3 ± tb*s/2, tb perpendicular to nb
tb=(-nb[1], nb[0])
b1=(cx+nb[0]*h/3+tb[0]*s/2, cz+nb[1]*h/3+tb[1]*s/2)
b2=(cx+nb[0]*h/3-tb[0]*s/2, cz+nb[1]*h/3-tb[1]*s/2)
print("apex",apex,"b1",b1,"b2",b2)
def refract(d, nrm, eta):  # d incident direction (travel), nrm outward normal of the surface on incoming side... generic
  c=-(d[0]*nrm[0]+d[1]*nrm[1])
  if c<0: nrm=(-nrm[0],-nrm[1]); c=-c; eta=1/eta
  k=1-(1-c*c)/(eta*eta)
  if k<0: return None
  ct=math.sqrt(k)
  return (d[0]/eta+(c/eta-ct)*nrm[0], d[1]/eta+(c/eta-ct)*nrm[1])
def seg_hit(o,d,p,q):
  # ray o+t d vs segment p-q
  ex,ez=q[0]-p[0],q[1]-p[1]
  den=d[0]*(-ez)-d[1]*(-ex)
  if abs(den)<1e-12: return None
  rx,rz=p[0]-o[0],p[1]-o[1]
  t=(rx*(-ez)-rz*(-ex))/den; u=(d[0]*rz-d[1]*rx)/den
  if t>1e-9 and 0<=u<=1: return t
  return None
edges=[(apex,b1),(b1,b2),(b2,apex)]
def outward(p,q):
  ex,ez=q[0]-p[0],q[1]-p[1]; nn=(ez,-ex); L=math.hypot(*nn); nn=(nn[0]/L,nn[1]/L)
  mx,mz=(p[0]+q[0])/2-cx,(p[1]+q[1])/2-cz
  if nn[0]*mx+nn[1]*mz<0: nn=(-nn[0],-nn[1])
  return nn
def trace(o,d,lam):
  eta=n(lam); inside=False
  for _ in range(3):
    best=None
    for (p,q) in edges:
      t=seg_hit(o,d,p,q)
      if t and (best is None or t<best[0]): best=(t,p,q)
    if not best: return o,d,inside
    t,p,q=best; o=(o[0]+d[0]*t,o[1]+d[1]*t)
    nd=refract(d,outward(p,q),eta)
    if nd is None: return None
    L=math.hypot(*nd); d=(nd[0]/L,nd[1]/L); inside=not inside
    o=(o[0]+d[0]*1e-7,o[1]+d[1]*1e-7)
  return o,d,inside
o,d,ins=trace((0,0),(0,-1),589.3)
print("exit",o,d,ins, "deviation deg", math.degrees(math.acos(-d[1])))
# find face with normal n1
for (p,q) in edges:
  on=outward(p,q)
  if abs(on[0]-n1[0])<1e-6: f1=(p,q)
mid=((f1[0][0]+f1[1][0])/2,(f1[0][1]+f1[1][1])/2)
shift=-mid[0]
apex=(apex[0]+shift,apex[1]); b1=(b1[0]+shift,b1[1]); b2=(b2[0]+shift,b2[1]); cx+=shift
edges=[(apex,b1),(b1,b2),(b2,apex)]
o,d,ins=trace((0,0),(0,-1),589.3)
print("shift",shift,"apex",apex,"b1",b1,"b2",b2)
print("exit",o,d, "deviation deg", math.degrees(math.acos(-d[1])))
light=(o[0]+d[0]*6,o[1]+d[1]*6)
print("light",light)
# camera angle at which each wavelength sees the light centre: scan angle phi (rotation of ray about y), ray dir = (sin phi, -cos phi)
def miss(phi,lam):
  r=trace((0,0),(math.sin(phi),-math.cos(phi)),lam)
  if r is None: return None
  o2,d2,_=r
  # signed distance of light centre from the ray line
  vx,vz=light[0]-o2[0],light[1]-o2[1]
  return d2[0]*vz-d2[1]*vx
def solve(lam):
  lo,hi=math.radians(-20),math.radians(20)
  # scan for sign change
  prev=None;N=4000
  for k in range(N+1):
    phi=lo+(hi-lo)*k/N; m=miss(phi,lam)
    if m is not None and prev is not None and prev[1]*m<0:
      a,b=prev[0],phi
      for _ in range(60):
        c=(a+b)/2; mc=miss(c,lam)
        if (miss(a,lam))*mc<=0: b=c
        else: a=c
      return math.degrees((a+b)/2)
    prev=(phi,m) if m is not None else None

# Camera: yaw PSI towards +x, image W x H, vertical fov VFOV (the values in scenes/prism.ron).
PSI=math.radians(2.9); W,H=512,160; VFOV=3.29
tan_x=math.tan(math.radians(VFOV)/2)*W/H
print("look_at (%.6f, 0, %.6f)"%(math.sin(PSI),-math.cos(PSI)))
print("light centre (%.4f, 0, %.4f)"%light)
print("predicted film column of the light's image per wavelength (nm: column):")
for lam in range(380,740,10):
  phi=math.radians(solve(lam))
  print("  %d: %.2f"%(lam, W/2*(1+math.tan(phi-PSI)/tan_x)))
# The prism as an OBJ (outward, counter-clockwise faces).
tri=[apex,b1,b2]; V=[(p[0],y,p[1]) for y in (-0.8,0.8) for p in tri]
def sub(a,b): return tuple(x-y for x,y in zip(a,b))
def cross(a,b): return (a[1]*b[2]-a[2]*b[1],a[2]*b[0]-a[0]*b[2],a[0]*b[1]-a[1]*b[0])
c3=(cx,0,cz); faces=[(0,1,2),(3,4,5)]+[f for i in range(3) for f in ((i,(i+1)%3,(i+1)%3+3),(i,(i+1)%3+3,i+3))]
with open('meshes/prism.obj','w') as fh:
  fh.write("# An equilateral N-SF11 prism (apex angle 60 degrees, side %.1f), axis along y, for scenes/prism.ron.\n"%s)
  fh.write("# Generated by scripts/prism_geometry.py: the camera ray along -z from the origin passes at\n# minimum deviation for 589.3 nm. Faces are counter-clockwise seen from outside.\n")
  for v in V: fh.write("v %.9f %.9f %.9f\n"%v)
  for f in faces:
    a,b,cc=[V[k] for k in f]; nn=cross(sub(b,a),sub(cc,a)); m=tuple((a[k]+b[k]+cc[k])/3 for k in range(3))
    if sum(x*y for x,y in zip(nn,sub(m,c3)))<0: f=(f[0],f[2],f[1])
    fh.write("f %d %d %d\n"%tuple(k+1 for k in f))
