# Optional tooling: writes scenes/prism.obj and scenes/prism-slit.obj (python3 scripts/gen-prism.py,
# run in scenes/). Traces the 550 nm ray of minimum deviation through an SF11 prism in 2D to
# place the slit. Nothing in the build or the tests needs it.
import math
def n_sf11(lnm):
    l2=(lnm*1e-3)**2
    B=[1.73759695,0.313747346,1.89878101]; C=[0.013188707,0.0623068142,155.23629]
    return math.sqrt(1+sum(b*l2/(l2-c) for b,c in zip(B,C)))
# 2D in (z, y). Prism: equilateral, side s, apex up, centroid at origin, then rotated by phi about x.
s=1.2; h=s*math.sqrt(3)/2
tri=[(-s/2,-h/3),(s/2,-h/3),(0,2*h/3)]  # (z,y): base left, base right, apex
n550=n_sf11(550)
i=math.asin(n550*0.5)  # min deviation incidence
# camera ray horizontal (-z) must hit right face (facing +z, up) at incidence i.
# right face normal unrotated: (cos30, sin30) in (z,y); rotated by phi: angle 30+phi from +z axis.
# incidence: angle between -d=(+1,0) and n = 30+phi -> need 30+phi = i  (tilting the face)
phi=i-math.radians(30)
def rot(p,a): z,y=p; return (z*math.cos(a)-y*math.sin(a), z*math.sin(a)+y*math.cos(a))
tri_r=[rot(p,phi) for p in tri]
print("phi deg", math.degrees(phi), "i deg", math.degrees(i))
def refract(d,nrm,eta):  # nrm faces against d; eta = n1/n2
    c=-(d[0]*nrm[0]+d[1]*nrm[1]); k=1-eta*eta*(1-c*c)
    if k<0: return None
    return (eta*d[0]+(eta*c-math.sqrt(k))*nrm[0], eta*d[1]+(eta*c-math.sqrt(k))*nrm[1])
def isect(o,d,a,b):
    # ray o+t d with segment a-b
    ex,ey=b[0]-a[0],b[1]-a[1]; det=d[0]*(-ey)-d[1]*(-ex)
    if abs(det)<1e-12: return None
    rx,ry=a[0]-o[0],a[1]-o[1]
    t=(rx*(-ey)-ry*(-ex))/det; u=(d[0]*ry-d[1]*rx)/det
    return (t,u) if t>1e-9 and 0<=u<=1 else None
def outward(a,b):
    ex,ey=b[0]-a[0],b[1]-a[1]; nz,ny=ey,-ex; L=math.hypot(nz,ny); nz,ny=nz/L,ny/L
    c=(sum(p[0] for p in tri_r)/3,sum(p[1] for p in tri_r)/3)
    if (a[0]-c[0])*nz+(a[1]-c[1])*ny<0: nz,ny=-nz,-ny
    return (nz,ny)
faces=[(tri_r[1],tri_r[2]),(tri_r[2],tri_r[0]),(tri_r[0],tri_r[1])]
def trace(o,d,lam):
    n=n_sf11(lam)
    best=None
    for a,b in faces:
        r=isect(o,d,a,b)
        if r and (best is None or r[0]<best[0]): best=(r[0],a,b)
    t,a,b=best; p=(o[0]+t*d[0],o[1]+t*d[1]); nr=outward(a,b)
    d2=refract(d,nr,1/n)
    best=None
    for a2,b2 in faces:
        if (a2,b2)==(a,b): continue
        r=isect(p,d2,a2,b2)
        if r and (best is None or r[0]<best[0]): best=(r[0],a2,b2)
    t,a2,b2=best; p2=(p[0]+t*d2[0],p[1]+t*d2[1]); nr2=outward(a2,b2)
    d3=refract(d2,(-nr2[0],-nr2[1]),n)
    return p,p2,d3
cam=(4.0,0.0)
p,p2,d3=trace(cam,(-1,0),550)
print("entry",p,"exit",p2,"dir",d3, "deviation deg", math.degrees(math.atan2(-d3[1],-d3[0])))
for lam in [420,480,550,620,680]:
    _,_,dd=trace(cam,(-1,0),lam); print(lam, "dev", math.degrees(math.atan2(-dd[1],-dd[0])))
L=3.0
sc=(p2[0]+L*d3[0], p2[1]+L*d3[1])
print("slit centre", sc)
# write OBJ: prism along x (length 3), cross-section tri_r; slit quad perpendicular to d3
with open("prism.obj","w") as f:
    f.write("# A 60-degree glass prism, axis along x (3 units), side 1.2, turned %.2f degrees about x\n"%math.degrees(phi))
    f.write("# so that a horizontal camera ray at 550 nm passes at minimum deviation in dense flint\n")
    f.write("# (SF11). Generated for valo's spectral demo (scenes/prism.json).\n")
    for x in (-1.5,1.5):
        for z,y in tri_r: f.write("v %.6f %.6f %.6f\n"%(x,y,z))
    f.write("f 1 2 3\nf 4 6 5\nf 1 4 5 2\nf 2 5 6 3\nf 3 6 4 1\n")
w=0.012  # slit half-width
perp=(-d3[1],d3[0])
with open("prism-slit.obj","w") as f:
    f.write("# A thin slit of light (%.3f wide, 4 long) facing the prism, %.1f units beyond its exit face\n"%(2*w,L))
    f.write("# along the 550 nm ray of minimum deviation. Generated for valo (scenes/prism.json).\n")
    for x in (-2,2):
        for sgn in (-1,1):
            f.write("v %.6f %.6f %.6f\n"%(x, sc[1]+sgn*w*perp[1], sc[0]+sgn*w*perp[0]))
    f.write("f 1 2 4 3\n")
