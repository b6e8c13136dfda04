# Mitsuba 3's `direct_projective` on geosens's 3D occluder scene
# (scenes/mesh/triangle.toml): the unit-square lamp at z = 2, the black
# triangle at z = 1, a white Lambertian floor patch 0.1 × 0.1 at the origin
# seen by a camera at z = 0.5 that covers exactly the patch, so
# E = π × the mean pixel (averaged over the patch, not at the point: the
# values differ from geosens's by the patch average). dE/dtx by forward-mode
# AD on the triangle's vertices. Prints each render's E, dE/dtx and time,
# then the mean over the renders with its standard error.
#
#   pip install mitsuba numpy      (variant llvm_ad_mono: a system LLVM >= 16,
#                                   e.g. Debian's libllvm19)
#   python3 benches/mitsuba_occluder.py SPP RENDERS
#
# Measured 2026-11-24 on 2 cores: `python3 benches/mitsuba_occluder.py 4096 5`
# gave dE/dtx = 0.183128 ± 0.000268 (0.146 %) in 32.7 s; geosens reached
# 0.150 % with `geosens mesh --scene scenes/mesh/triangle.toml --method
# rendering --paths 4400000 --threads 2` in 1.86 s.
import mitsuba as mi, drjit as dr, time, sys, numpy as np
mi.set_variant('llvm_ad_mono')
tri = np.array([[0.39106729782512123, 0.10910404133226792, 1.0], [0.053280749827369994, 0.1859171130828683, 1.0], [0.15565195234750875, -0.14502115441513613, 1.0]])
import os, tempfile
obj = os.path.join(tempfile.mkdtemp(), 'tri.obj')
with open(obj, 'w') as f:
    for v in tri: f.write('v %r %r %r\n' % tuple(float(c) for c in v))
    f.write('f 1 2 3\n')
spp = int(sys.argv[1]) if len(sys.argv) > 1 else 1024
res = 32
scene = mi.load_dict({
    'type': 'scene',
    'integrator': {'type': 'direct_projective'},
    'sensor': {'type': 'perspective', 'fov': 2*np.degrees(np.arctan(0.05/0.5)),
               'to_world': mi.ScalarTransform4f().look_at(origin=[0,0,0.5], target=[0,0,0], up=[0,1,0]),
               'film': {'type': 'hdrfilm', 'width': res, 'height': res, 'rfilter': {'type': 'box'}, 'pixel_format': 'luminance', 'sample_border': True},
               'sampler': {'type': 'independent', 'sample_count': spp}},
    'lamp': {'type': 'rectangle', 'to_world': mi.ScalarTransform4f().translate([0,0,2]).rotate([1,0,0],180).scale(0.5),
             'emitter': {'type': 'area', 'radiance': {'type': 'rgb', 'value': 1.0}}},
    'floor': {'type': 'rectangle', 'to_world': mi.ScalarTransform4f().scale(0.05),
              'bsdf': {'type': 'diffuse', 'reflectance': {'type': 'rgb', 'value': 1.0}}},
    'occ': {'type': 'obj', 'filename': obj, 'face_normals': True,
            'bsdf': {'type': 'diffuse', 'reflectance': {'type': 'rgb', 'value': 0.0}}},
})
params = mi.traverse(scene)
key = 'occ.vertex_positions'
v0 = dr.unravel(mi.Point3f, params[key])
pi = mi.Float(0.0)
dr.enable_grad(pi)
params[key] = dr.ravel(v0 + mi.Vector3f(pi, 0, 0))
params.update()
vals = []
for r in range(int(sys.argv[2]) if len(sys.argv) > 2 else 3):
    t = time.time()
    img = mi.render(scene, params, seed=r, spp=spp)
    e = dr.mean(img, axis=None) * dr.pi
    dr.forward(pi)
    g = dr.grad(e)
    dr.eval(e, g)
    vals.append((float(np.array(e).ravel()[0]), float(np.array(g).ravel()[0]), time.time()-t))
    print('render %d: E %.6f dE/dtx %.6f  %.1f s' % (r, vals[-1][0], vals[-1][1], vals[-1][2]), flush=True)
    params[key] = dr.ravel(v0 + mi.Vector3f(pi, 0, 0)); params.update()
g = np.array([v[1] for v in vals]); e = np.array([v[0] for v in vals])
print('mean E %.6f ± %.6f, dE/dtx %.6f ± %.6f (%.3f%%), total %.1f s' % (e.mean(), e.std(ddof=1)/np.sqrt(len(e)), g.mean(), g.std(ddof=1)/np.sqrt(len(g)), 100*g.std(ddof=1)/np.sqrt(len(g))/abs(g.mean()), sum(v[2] for v in vals)))
