// One object's ray march (thesis §6.3, Eq. 5.10–5.12), instantiated once per object of the scene
// by viewer/raymarch_shader.cpp in place of raymarch.frag's "// @OBJECTS@" line: every '@' becomes
// the object's index, and the object's scope #defines its volume layout
// (gl::VolumeTextureLayout::glslDefines) and renames common/volume.glsl's samplers and field
// accessors to its own (volumeSigmaA here is this object's), so each object samples its own
// textures with no branches on uniforms (llvmpipe executes uniform branches even when false; GLSL
// 3.30 cannot index sampler arrays with a variable). Per-object defines: HAS_<FIELD> (the fields
// its volume has) and SHARP_FACES; program-wide: GROUND, FRESNEL, ATTENUATION, EMISSION,
// SCATTERING, DISPERSION, NO_REFRACTION, RK4, SKIP_HOMOGENEOUS.
//
// The ray is carried into the volume's own space (§6.3.1: x' = M⁻¹x; ∇n' = M⁻ᵀ∇n is the stored
// field itself there), marched with arc length s through the box of the non-trivial region, and
// carried back to the world when it leaves. The march itself, march@, is the last function of this
// file: a short loop over the named steps defined above it, in the order it calls them.

uniform sampler3D uO@Bricks;  // homogeneousBricks (viewer/volume_analysis.h), nearest filtering
#ifdef HAS_RECEIVER
uniform sampler2D uO@Receiver;  // the receiver map of the ground (core/receiver_map.h), RGB W/m² (RECEIVER_GREY: R alone)
#endif

// The light a reflection (or any branch the march does not follow) sees: the ground or the
// environment (defined below, after the ground's helpers it uses).
vec3 branchRadiance@(vec3 pVol, vec3 dVol);
void takeBranch@(inout Ray r, vec3 weight, vec3 pVol, vec3 dVol, bool fromOutside);

// The state of a ray inside this object, in the volume's own space.
struct March@ {
  vec3 x;           // position
  vec3 w;           // n·dx/ds (Eq. 4.8): |w| = n along an exact ray (docs/physics.md)
  float n;          // n at the last sample
  vec3 tau;         // optical depth ∫σa ds in this object (Beer–Lambert, Eq. 3.4: T = exp(−τ))
  bool stopped;     // the ray ended here: ground, opaque embedding, or absorbed
  vec3 xStepStart;  // where the last step began (a sharp face takes it back there)
  // The boundary layer the ray is in: it begins where |∇n| exceeds the threshold and ends where
  // |∇n| falls below a 16th of it (quiet).
  bool inLayer;
  float gradPeak2;
  vec3 gradPeak;    // ∇n where |∇n| peaked: the layer's normal
  vec3 uvwPeak;
  // n, direction and optical depth at the last quiet sample before the layer (the direction
  // the ray entered with, until then).
  float nBefore;
  vec3 dBefore;
  vec3 tauBefore;
  // The object's box and step, and the ground plane (GROUND), in the volume's own space.
  vec3 bmin, invExtent;
  float h;
  float threshold2, quiet2;  // |∇n|² where a boundary layer begins, and where it ends
  vec3 groundNormal;
  float groundOffset;  // the ground is {x : x·groundNormal = groundOffset}
  bool groundPassed;   // found below the ground's plane once (belowGround@, metGround@)
  int medium;       // sharp interfaces (HAS_INTERFACES): the material slot the ray is in, −1 air
  vec4 dist;        // the slot distances at x (HAS_INTERFACES), fetched where x last moved
  vec3 groundHit;   // where the last step met the ground (world; the ground event)
  vec3 uvwOpaque;   // where the ray met an opaque embedding (the opaque event)
  float hsLast;     // the length of the step that crossed a sharp surface (the crossing event)
};

// Radiance of an opaque embedding of diffuse albedo ρ at uvw: ρE/π with the baked irradiance E
// (none without it), plus the unoccluded environment.
vec3 opaqueRadiance@(vec3 albedo, vec3 uvw) {
  return albedo * (volumeIrradiance(uvw) * INV_PI + uAmbientRadiance);
}

// The baked irradiance on the ground at world point xw, if it lies inside this volume and the
// volume has no receiver map (whose change, receiverChange@, is the ground's light where it has
// one): E on the ground = irradiance · max(0, N·(−l)) with the baked light direction l
// (thesis §3.2.2). Returns
// the weight of the bake against the unoccluded light: 0 outside the box, rising to 1 over the
// outer kGroundBlendVoxels, so the edge of the baked region leaves no seam.
#ifdef GROUND
float bakedGroundIrradiance@(vec3 xw, out vec3 E) {
  E = vec3(0.0);
  float weight = 0.0;
#if defined(HAS_IRRADIANCE) && defined(HAS_LIGHT_DIR) && !defined(HAS_RECEIVER)
  vec3 x = (uObjWorldToVol[@] * vec4(xw, 1.0)).xyz;
  vec3 uvw = (x - uObjBoundsMin[@]) / (uObjBoundsMax[@] - uObjBoundsMin[@]);
  // Distance to each face, in voxels, past the outermost voxel centres (half a voxel in).
  vec3 fromFace = min(uvw, 1.0 - uvw) / (2.0 * uObjHalfVoxel[@]) - 0.5;
  if (min(min(fromFace.x, fromFace.y), fromFace.z) > 0.0) {
    vec3 normal = normalize(mat3(uObjWorldToVol[@]) * uGroundNormal);
    vec3 l = volumeLightDir(uvw);
    E = volumeIrradiance(uvw) * max(0.0, -dot(normal, l));
    // The same distances measured within the ground plane: a face parallel to the ground never
    // meets it (a box's floor just under the ground must not fade the bake).
    vec3 inPlane = fromFace / max(sqrt(max(1.0 - normal * normal, 0.0)), 1e-3);
    weight = clamp(min(min(inPlane.x, inPlane.y), inPlane.z) / kGroundBlendVoxels, 0.0, 1.0);
  }
#endif
  return weight;
}
#endif

// The change this object's bake makes to the ground's planar irradiance at world point xw: its
// receiver map there minus the direct light it was baked with (its shadow, its caustic, what it
// reflects onto the ground). The texture (viewer/shadow_edge.h) holds the map with the direct
// light its geometric shadow takes added back, and in .a the shadow's clearance, whose sign cuts
// the direct light off at the pixel: the change is rgb − D where a ≥ 0, rgb − 2D where a < 0.
// False where the map does not reach (GROUND, HAS_RECEIVER).
#ifdef GROUND
bool receiverChange@(vec3 xw, out vec3 change) {
  change = vec3(0.0);
  bool covered = false;
#ifdef HAS_RECEIVER
  vec3 x = (uObjWorldToVol[@] * vec4(xw, 1.0)).xyz;
  vec3 q = x - uObjRecvPoint[@];
  vec2 st = (vec2(dot(q, uObjRecvU[@]), dot(q, uObjRecvV[@])) - uObjRecvOrigin[@]) / uObjRecvSize[@];
  covered = all(greaterThanEqual(st, vec2(0.0))) && all(lessThanEqual(st, vec2(1.0)));
  if (covered) {
    vec3 normal = cross(uObjRecvU[@], uObjRecvV[@]);
#ifdef RECEIVER_GREY
    vec2 g = texture(uO@Receiver, st).rg;  // a grey map: R = G = B, and the clearance
    vec4 m = vec4(g.xxx, g.y);
#else
    vec4 m = texture(uO@Receiver, st);
#endif
    vec3 direct = lightIrradiance(uObjRecvLightPos[@], uObjRecvLightPower[@], uObjRecvLightSpot[@],
                                  uObjRecvLightSpotScale[@], x, normal);
    change = m.rgb - direct * (m.a >= 0.0 ? 1.0 : 2.0);
  }
#endif
  return covered;
}
#endif

// Sharp interfaces (HAS_INTERFACES; core/interfaces.h, docs/physics.md): the material at a point
// is the first slot whose distance is negative. Its n is the slot's constant (SLOT_IOR, with the
// Cauchy term of its SLOT_DISPERSION) or, in a graded slot, the ior field.
int materialAt@(vec4 d) {
#ifdef HAS_INTERFACES
  for (int k = 0; k < INTERFACE_SLOTS; ++k)
    if (d[k] < 0.0) return k;
#endif
  return -1;
}

// n and ∇n at uvw for the wavelength whose Cauchy term (1/λ² − 1/λ_d²) is `cauchy` (thesis
// §3.2.7, docs/volume-format.md): n(λ) = n + B·cauchy; ∇n scales with n − 1 (B ∝ n − 1 within one
// material). ior and ior_grad share one RGBA texture (SceneRenderer checks): one fetch for both.
vec4 refractiveIndex@(vec3 uvw, float cauchy, int medium) {
#ifdef HAS_INTERFACES
#ifdef DISPERSION
  float slotN = medium < 0 ? 1.0 : SLOT_IOR[max(medium, 0)] + SLOT_DISPERSION[max(medium, 0)] * cauchy;
#else
  float slotN = medium < 0 ? 1.0 : SLOT_IOR[max(medium, 0)];
#endif
#ifdef CONSTANT_SLOTS
  // No graded slot: no fetch (llvmpipe would fetch, masked), and no ior texture (SceneRenderer
  // leaves it out).
  return vec4(slotN, 0.0, 0.0, 0.0);
#else
  if (medium < 0 || SLOT_GRADED[medium] < 0.5) return vec4(slotN, 0.0, 0.0, 0.0);
#endif
#endif
#ifndef CONSTANT_SLOTS
  vec4 optics = texture(IOR_SAMPLER, uvw);  // ior (r), ior_grad (gba)
#if defined(DISPERSION) && defined(HAS_DISPERSION)
  float B = volumeDispersion(uvw);
  optics.gba *= 1.0 + cauchy * B / max(optics.r - 1.0, 1e-3);
  optics.r += B * cauchy;
#endif
#ifdef NO_REFRACTION
  optics.gba = vec3(0.0);
#endif
  return optics;
#endif
}

// δ·R·L_r and the transmission factor (Eq. 5.4 in Eq. 5.10, docs/physics.md; FRESNEL), once the
// ray has crossed a boundary layer: n1 before it, n2 after it, the incident direction dIn (volume
// space) and the normal where |∇n| peaked; TBefore is the transmittance the ray had before it.
void crossBoundary@(inout Ray r, float n1, float n2, vec3 dIn, vec3 gradPeak, vec3 uvwPeak, vec3 TBefore) {
#ifdef FRESNEL
  vec3 normal = normalize(gradPeak);
  float R = fresnelReflectance(n1, n2, abs(dot(dIn, normal)));
  // R = 1: total internal reflection, which the ray equation already performed (the ray is the
  // reflected one and keeps its energy). Equal n: the ray came back out of the layer.
  if (R >= 1.0 || abs(n2 - n1) <= 1e-3) return;
  r.T *= 1.0 - R;
  // Light reflected towards the eye from outside the denser medium. A reflection seen from inside
  // (n falls) would need the light that comes back through the object, which one ray does not
  // follow; it is left out (its share is of the order of R).
  if (n2 > n1) {
    // The volume's reflection tint (none without a reflect field: weight 0).
    vec4 reflectTint = volumeReflect(uvwPeak);
    vec3 tint = mix(vec3(1.0), reflectTint.rgb, clamp(reflectTint.a, 0.0, 1.0));
    vec3 pPeak = uObjBoundsMin[@] + uvwPeak * (uObjBoundsMax[@] - uObjBoundsMin[@]);
    takeBranch@(r, TBefore * R * tint, pPeak, reflect(dIn, normal), n1 < 1.001);
  }
#endif
}

// n, direction and optical depth at a quiet sample (FRESNEL): the state before any boundary layer
// ahead. Fresnel takes n, the direction and T before a layer from its last quiet sample, so the
// smoothed tails do not bias R (at 80° a 0.5 % error in n·cos θ is 2 % in R).
void rememberStateBeforeLayer@(inout March@ m, float n, vec3 d) {
#ifdef FRESNEL
  m.nBefore = n;
  m.dBefore = d;
  m.tauBefore = m.tau;
#endif
}

// Into the volume's own space (§6.3.1: x' = M⁻¹x), a hair inside the box the ray arrived at, with
// w = n·d; nothing gathered yet.
March@ enterVolume@(Ray r, float cauchy) {
  March@ m;
  mat4 toVolume = uObjWorldToVol[@];
  m.bmin = uObjBoundsMin[@];
  m.invExtent = 1.0 / (uObjBoundsMax[@] - m.bmin);
  m.h = uObjStep[@];
  vec3 d = normalize(mat3(toVolume) * r.d);
  m.x = (toVolume * vec4(r.x, 1.0)).xyz + d * (1e-3 * m.h);
  m.dist = volumeInterfaces((m.x - m.bmin) * m.invExtent);
  m.groundHit = vec3(0.0);
  m.uvwOpaque = vec3(0.0);
  m.hsLast = 0.0;
  m.medium = materialAt@(m.dist);
  vec4 optics = refractiveIndex@((m.x - m.bmin) * m.invExtent, cauchy, m.medium);
  m.n = optics.r;
  m.w = d * m.n;
  m.tau = vec3(0.0);
  m.stopped = false;
  m.xStepStart = m.x;
  m.inLayer = false;
  m.gradPeak2 = 0.0;
  m.gradPeak = vec3(0.0);
  m.uvwPeak = vec3(0.0);
  m.nBefore = m.n;
  m.dBefore = d;
  m.tauBefore = vec3(0.0);
  m.threshold2 = uObjBoundaryGrad[@] * uObjBoundaryGrad[@];
  m.quiet2 = m.threshold2 * (1.0 / 256.0);
#ifdef GROUND
  // A plane goes to a plane: the normal by the inverse transpose (M⁻ᵀ of toVolume is the
  // transpose of toWorld's linear part), the offset through a point of it.
  m.groundNormal = normalize(transpose(mat3(uObjVolToWorld[@])) * uGroundNormal);
  m.groundOffset = dot((toVolume * vec4(uGroundPoint, 1.0)).xyz, m.groundNormal);
  m.groundPassed = false;
#endif
  return m;
}

// Entering through a face the material touches (SHARP_FACES: SceneRenderer found n ≠ 1 there):
// the face is a sharp interface, Snell's law and Fresnel (corrected Eq. 3.6), exactly.
void enterSharpFace@(inout Ray r, inout March@ m) {
#ifdef SHARP_FACES
  vec3 d = m.dBefore;  // the direction the ray arrived with
  vec3 extent = uObjBoundsMax[@] - m.bmin;
  vec3 rel = (m.x - m.bmin) * m.invExtent;
  vec3 toFace = min(rel, 1.0 - rel) * extent;
  float nearest = min(min(toFace.x, toFace.y), toFace.z);
  if (abs(m.n - 1.0) > 1e-3 && nearest < 0.01 * m.h) {
    vec3 outward = vec3(equal(toFace, vec3(nearest))) * sign(rel - 0.5);
    outward = normalize(outward);
#ifdef FRESNEL
    float R = fresnelReflectance(1.0, m.n, abs(dot(d, outward)));
    takeBranch@(r, r.T * R, m.x, reflect(d, outward), true);
    r.T *= 1.0 - R;
#endif
    d = refract(d, outward, 1.0 / m.n);
    m.w = d * m.n;
    m.dBefore = d;
  }
#endif
}

// The light along the branch a sharp face does not follow (volume-space point and direction): it
// goes straight from the face, so it meets the ground (GROUND) where it heads down onto it (a face
// resting on the ground sends its light there, not into the sky below the horizon), and the
// environment otherwise.
vec3 branchRadiance@(vec3 pVol, vec3 dVol) {
  vec3 dw = normalize(mat3(uObjVolToWorld[@]) * dVol);
#ifdef GROUND
  vec3 pw = (uObjVolToWorld[@] * vec4(pVol, 1.0)).xyz;
  float down = -dot(dw, uGroundNormal);
  if (down > 0.0) {
    // A face a hair under the ground (its surface is found to a fraction of a voxel) meets it here.
    vec3 hit = pw + dw * (max(dot(pw - uGroundPoint, uGroundNormal), 0.0) / down);
    if (onGround(hit)) return groundRadiance(hit);
  }
#endif
  return environmentRadiance(dw, uReflectionLod);
}

// The branch a surface does not follow, of weight `weight` (volume-space point and direction): the
// first one that leaves the object's outside for the air, on the primary ray, is recorded for a
// trace of its own through the scene (REFLECT_OBJECTS; raymarch.frag gRecordBranch); any other is
// looked up here (branchRadiance@).
void takeBranch@(inout Ray r, vec3 weight, vec3 pVol, vec3 dVol, bool fromOutside) {
#ifdef REFLECT_OBJECTS
  if (gRecordBranch && fromOutside && !r.dispersed && dot(gBranchWeight, vec3(1.0)) <= 0.0) {
    gBranchWeight = weight;
    gBranchX = (uObjVolToWorld[@] * vec4(pVol, 1.0)).xyz;
    gBranchD = normalize(mat3(uObjVolToWorld[@]) * dVol);
    gBranchObject = @;
    return;
  }
#endif
  r.radiance += weight * branchRadiance@(pVol, dVol);
}

// Whether the ray, in air, is below the ground plane (GROUND) and has not been found below it
// before: the one test a step makes (a dot product), the crossing itself is metGround@'s. With sharp
// interfaces the ground is met from the air only: inside a material the height is not followed,
// so a face resting on the ground decides first (Fresnel, total internal reflection) and the ray
// meets the ground once it has left the face downwards; the face is found to a fraction of a
// voxel, a hair above or below the plane, which must not decide whether a reflection happens.
bool belowGround@(March@ m) {
#ifdef GROUND
#ifdef HAS_INTERFACES
  bool inAir = m.medium < 0;
#else
  bool inAir = true;
#endif
  return inAir && !m.groundPassed && dot(m.x, m.groundNormal) <= m.groundOffset;
#else
  return false;
#endif
}

// The ground event: whether the last step (from m.xStepStart to m.x) came down through the
// ground's plane onto the ground itself, and where (m.groundHit, world); shadeGround@ ends the
// ray there. Otherwise (the step began below the plane, or the plane is crossed beyond the
// ground's extent) the ray goes on and the plane is not looked at again in this object: a ray
// below it does not come back up and down onto it (steps are straight in air).
bool metGround@(inout March@ m) {
#ifdef GROUND
  m.groundPassed = true;
  float s0 = dot(m.xStepStart, m.groundNormal) - m.groundOffset;
  float s1 = dot(m.x, m.groundNormal) - m.groundOffset;
  if (s0 > 0.0) {
    vec3 hit = mix(m.xStepStart, m.x, s0 / (s0 - s1));
    m.groundHit = (uObjVolToWorld[@] * vec4(hit, 1.0)).xyz;
    return onGround(m.groundHit);
  }
#endif
  return false;
}

// The ray ends on the ground at m.groundHit: ρE/π there (GROUND), added by trace.
void shadeGround@(inout Ray r, inout March@ m) {
#ifdef GROUND
  r.grounded = true;
  r.groundWeight = r.T * exp(-m.tau);
  r.x = m.groundHit;
  r.done = true;
  m.stopped = true;
#endif
}

// Whether the ray has left the box of the non-trivial region (empty-space skipping: outside it
// the ray goes straight and gathers nothing, viewer/volume_analysis.h activeRegion).
bool leftActiveRegion@(March@ m) {
  return any(lessThan(m.x, uObjActiveMin[@])) || any(greaterThan(m.x, uObjActiveMax[@]));
}

// Leaving through a face the material touches (SHARP_FACES): refraction out by Snell's law with
// Fresnel's transmission, or total internal reflection back in. True when reflected back: the ray
// is taken back to where the step began, to take it again reflected.
bool reflectedAtSharpFace@(inout Ray r, inout March@ m) {
#ifdef SHARP_FACES
  if (m.n > 1.0 + 1e-3 && (any(lessThan(m.x, m.bmin)) || any(greaterThan(m.x, uObjBoundsMax[@])))) {
    vec3 outward = normalize(step(uObjBoundsMax[@], m.x) - step(m.x, m.bmin));
    gSurfaceCode = surfaceCode(outward);
    vec3 dir = normalize(m.w);
    // Back onto the face the step crossed (the first one along the step).
    vec3 face = mix(m.bmin, uObjBoundsMax[@], step(0.0, outward));
    vec3 along = (face - m.xStepStart) / (m.x - m.xStepStart);
    along = mix(vec3(1.0), along, abs(outward));
    m.x = mix(m.xStepStart, m.x, clamp(min(min(along.x, along.y), along.z), 0.0, 1.0));
    float R = fresnelReflectance(m.n, 1.0, dot(dir, outward));
    if (R >= 1.0) {
      m.w = reflect(m.w, outward);
      m.x = m.xStepStart;
#ifdef HAS_INTERFACES
      m.dist = volumeInterfaces((m.x - m.bmin) * m.invExtent);
#endif
      return true;
    }
#ifdef FRESNEL
    r.T *= 1.0 - R;
#endif
    m.w = refract(dir, -outward, m.n);
  }
#endif
  return false;
}

// Empty-space skipping inside the medium (SKIP_HOMOGENEOUS): in a homogeneous brick (n constant,
// no ∇n, constant σa, nothing else, around it too; viewer/volume_analysis.h) the ray is straight,
// so it crosses the brick in one step, Beer–Lambert with σa constant. True when it did.
bool skipHomogeneousBrick@(inout March@ m, vec3 uvw) {
#ifdef SKIP_HOMOGENEOUS
  if (texture(uO@Bricks, uvw).r > 0.5) {
    vec3 dir = normalize(m.w);
    vec3 brickSize = uObjBrickSize[@];
    vec3 brickLo = m.bmin + floor((m.x - m.bmin) / brickSize) * brickSize;
    // Distance to the brick's exit face; axes the ray runs parallel to never end it.
    vec3 toFace = abs(mix(brickLo, brickLo + brickSize, step(0.0, dir)) - m.x) / max(abs(dir), vec3(1e-12));
    toFace = mix(vec3(1e30), toFace, greaterThan(abs(dir), vec3(1e-8)));
    float L = min(min(toFace.x, toFace.y), toFace.z) + 0.01 * m.h;
    if (!m.inLayer) rememberStateBeforeLayer@(m, length(m.w), dir);  // a quiet stretch
#if defined(ATTENUATION) && defined(SIGMA_A_BY_MATERIAL)
    m.tau += MEDIUM_SIGMA_A(m.medium) * (L * uObjLengthScale[@] * mediumShare@(m, m.x, m.x + dir * L));  // Beer–Lambert, σa constant here
#elif defined(ATTENUATION) && defined(HAS_SIGMA_A)
    m.tau += volumeSigmaA(uvw) * (L * uObjLengthScale[@]);
#endif
    m.xStepStart = m.x;  // a step like any other for the events after it (the ground, a sharp face)
    m.x += dir * L;
#ifdef HAS_INTERFACES
    m.dist = volumeInterfaces((m.x - m.bmin) * m.invExtent);
#endif
    return true;
  }
#endif
  return false;
}

// Whether an opaque embedding is at uvw (HAS_OPAQUE): its indicator over ½.
bool metOpaque@(inout March@ m, vec3 uvw) {
#ifdef HAS_OPAQUE
  m.uvwOpaque = uvw;
  return volumeOpaque(uvw).a > 0.5;
#else
  return false;
#endif
}

// The opaque embedding stops the ray: ρE/π + ambient, with the albedo interpolated with the
// indicator, divided by it (premultiplied at the edge).
void shadeOpaque@(inout Ray r, inout March@ m) {
#ifdef HAS_OPAQUE
  vec4 opaque = volumeOpaque(m.uvwOpaque);
  r.radiance += r.T * exp(-m.tau) * opaqueRadiance@(opaque.rgb / opaque.a, m.uvwOpaque);
  r.x = (uObjVolToWorld[@] * vec4(m.x, 1.0)).xyz;
  r.done = true;
  m.stopped = true;
#endif
}

// Follows the boundary layer at this sample (∇n = grad, |∇n|² = grad2; quiet: below a 16th of the
// threshold). Where a layer ends, |w| is set back to n along the layer's normal (the gradient
// where it peaked), keeping the component across it: n·sin θ, Snell's law; then Fresnel
// (crossBoundary). Elsewhere |w| = n holds by itself (w changes only where ∇n ≠ 0), so the steps
// do not renormalise (llvmpipe: it was half the cost of a step).
void followBoundaryLayer@(inout Ray r, inout March@ m, vec3 grad, float grad2, bool quiet, vec3 uvw) {
#ifdef HAS_INTERFACES
  return;  // n is sharp: crossInterface does what a smoothed layer does here
#endif
  if (!m.inLayer && quiet) rememberStateBeforeLayer@(m, m.n, normalize(m.w));
  if (m.inLayer ? !quiet : grad2 > m.threshold2) {
    if (!m.inLayer || grad2 > m.gradPeak2) {
      m.gradPeak = grad;
      m.gradPeak2 = grad2;
      m.uvwPeak = uvw;
    }
    m.inLayer = true;
  } else if (m.inLayer) {
    m.inLayer = false;
    m.w = renormalised(m.w, m.n, m.gradPeak);
    crossBoundary@(r, m.nBefore, m.n, m.dBefore, m.gradPeak, m.uvwPeak, r.T * exp(-m.tauBefore));
  }
}

// The share of the straight stretch a → b (volume coordinates) that the air's medium fills: with
// smoke in a box (AIR_BOX, core/interfaces.h airMediumBox; MEDIUM_SIGMA_A and MEDIUM_SCATTER give
// the air's inside it) the part of a → b in the box (slabs), else all of it.
float mediumShare@(March@ m, vec3 a, vec3 b) {
#ifdef AIR_BOX
  return m.medium >= 0 ? 1.0 : boxShare(a, b, AIR_BOX_MIN, AIR_BOX_MAX);
#else
  return 1.0;
#endif
}

// Beer–Lambert over the step hs (Eq. 3.4, per channel: T = exp(−τ)). σa is the constant of the
// material the ray is in where every material has one (MEDIUM_SIGMA_A, volume_analysis.h
// slotMedia), else fetched, only inside the box where it is not 0 (absorbingRegion).
void absorb@(inout March@ m, vec3 uvw, float hs) {
#if defined(ATTENUATION) && defined(SIGMA_A_BY_MATERIAL)
  m.tau += MEDIUM_SIGMA_A(m.medium) * hs;  // constant in the material the ray is in: no fetch
#elif defined(ATTENUATION) && defined(HAS_SIGMA_A)
  vec3 x = m.bmin + uvw * (uObjBoundsMax[@] - m.bmin);  // uvw's point (the step's middle)
  if (all(greaterThanEqual(x, uObjAbsorbingMin[@])) && all(lessThanEqual(x, uObjAbsorbingMax[@])))
    m.tau += volumeSigmaA(uvw) * hs;
#endif
}

// T·L_e·Δs: the medium's own emission (Eq. 5.4 in Eq. 5.10).
void emit@(inout Ray r, March@ m, vec3 uvw, float hs) {
#if defined(EMISSION) && defined(HAS_EMISSION)
  r.radiance += r.T * exp(-m.tau) * volumeEmission(uvw) * hs;
#endif
}

// T·ω̂·L_s·Δs: the baked irradiance scattered towards the eye by Henyey–Greenstein (Eq. 5.4, 5.7
// in Eq. 5.10; the 3D-normalised phase function, not Eq. 3.5).
void inScatter@(inout Ray r, March@ m, vec3 uvw, float hs) {
#if defined(SCATTERING) && defined(HAS_SCATTER) && defined(HAS_IRRADIANCE) && defined(HAS_LIGHT_DIR)
#ifdef MEDIUM_SCATTER
  vec2 scatter = MEDIUM_SCATTER(m.medium);  // constant in the material the ray is in: no fetch
#else
  vec2 scatter = volumeScatter(uvw);
#endif
  if (scatter.x > 0.0) {
    vec3 l = volumeLightDir(uvw);
    float cosTheta = dot(l, -normalize(m.w));
#if defined(ATTENUATION) && defined(SIGMA_A_BY_MATERIAL)
    // σa is constant over the step (absorb@ has added its x = σa·hs to τ): the light scattered at
    // s within it is attenuated by exp(−τ + x − σa·s), and ∫₀^hs of that is exp(−τ)·(eˣ − 1)/σa.
    vec3 x = MEDIUM_SIGMA_A(m.medium) * hs;
    vec3 along = hs * mix((exp(x) - 1.0) / max(x, vec3(1e-30)), 1.0 + 0.5 * x, lessThan(x, vec3(1e-3)));
#else
    vec3 along = vec3(hs);
#endif
    r.radiance += r.T * exp(-m.tau) * scatter.x * henyeyGreenstein(scatter.y, cosTheta) *
                  volumeIrradiance(uvw) * along;
  }
#endif
}

// The step: far from any boundary (|∇n| under a 16th of the boundary threshold) it doubles; the
// next boundary layer is still resolved, and the renormalisation across ∇n keeps the direction
// after it exact (Snell's law in a layered medium). With sharp interfaces it doubles only more
// than two voxels from every surface, so that no thin wall is stepped over. With sharp
// interfaces between materials of constant n, and nothing along the ray that needs samples
// (emission, scattering), the ray is straight up to the next surface, so the step goes as far as
// the distance field allows (sphere tracing): the trilinear interpolant of distances that change
// by at most one per unit length changes by at most √3 per unit length (|∂d/∂x_i| ≤ 1 on every
// axis), so no surface lies within nearest/√3 (the field is clamped to ±4 voxels: steps up to
// 2.3 voxels; SKIP_TO_SURFACES, the viewer's empty-space skipping). σa is taken at the step's
// middle, constant within a material. Where scattering must be sampled, it is the same but at most
// two voxels when every material's ω̂ is a constant (MEDIUM_SCATTER) and the ray is in one that
// scatters, else the fixed steps above.
float stepLength@(March@ m, vec3 uvw, float grad2) {
  bool quiet = grad2 <= m.quiet2;
#ifdef HAS_INTERFACES
  vec4 d = abs(m.dist);  // at m.x
  float nearest = min(min(d.x, d.y), min(d.z, d.w));
#if defined(SKIP_TO_SURFACES) && defined(CONSTANT_SLOTS) && !(defined(EMISSION) && defined(HAS_EMISSION))
#if !(defined(SCATTERING) && defined(HAS_SCATTER))
  return max(m.h, nearest * 0.57735);
#elif defined(MEDIUM_SCATTER)
  // In a scattering material the baked light is sampled at the middle of steps of at most two
  // voxels (4h at the default step of half a voxel: as close to a march of eighth-voxel steps as
  // steps of one voxel sampled at their start, BENCHMARKS.md); in the others the ray steps on to
  // the next surface.
  float reach = max(m.h, nearest * 0.57735);
  bool scatters = MEDIUM_SCATTER(m.medium).x > 0.0;
#ifdef AIR_BOX
  // Smoke in the air: sampled near its box (a step from outside may reach 2.3 voxels into it).
  scatters = scatters && (m.medium >= 0 || all(greaterThan(m.x, AIR_BOX_MIN - 4.0 * m.h)) &&
                                               all(lessThan(m.x, AIR_BOX_MAX + 4.0 * m.h)));
#endif
  return scatters ? min(reach, 4.0 * m.h) : reach;
#endif
#endif
  quiet = quiet && nearest > 4.0 * m.h;
#endif
  return quiet ? 2.0 * m.h : m.h;
}

// What the medium does over the step hs: one term of the sum of Eq. 5.10 with
// L_c = ω̂·L_s + L_e (Eq. 5.4; δ·R·L_r comes at the boundaries), and its attenuation, sampled at
// uvw, the step's middle (the midpoint rule; it runs after the step, once the step is known not
// to cross a sharp surface, or from crossInterface@ up to the surface).
void gatherMedium@(inout Ray r, inout March@ m, vec3 uvw, float hs) {
  float ds = hs * uObjLengthScale[@];  // the step in world units: σa, L_e and the baked light are per world unit
#ifdef AIR_BOX
  // The step is straight (the air's n is 1): its ends from its middle and direction.
  vec3 middle = m.bmin + uvw / m.invExtent, halfStep = (0.5 * hs) * normalize(m.w);
  float inMedium = ds * mediumShare@(m, middle - halfStep, middle + halfStep);
#else
  float inMedium = ds;
#endif
  absorb@(m, uvw, inMedium);
  emit@(r, m, uvw, ds);
  inScatter@(r, m, uvw, inMedium);
}

// One step of the ray equation in arc length (Eq. 5.11/5.12, the discrete Eq. 4.8/4.9):
// dx/ds = w/n, dw/ds = ∇n, with n and ∇n = grad at the step's start. Euler: the position with the
// mid-step w (second order in the drift); RK4: classical Runge–Kutta, three more fetches of n, ∇n.
void stepRay@(inout March@ m, vec3 grad, float hs, float cauchy) {
  m.xStepStart = m.x;
#ifdef RK4
  vec3 k1x = m.w / m.n, k1w = grad;
  vec4 o2 = refractiveIndex@((m.x + 0.5 * hs * k1x - m.bmin) * m.invExtent, cauchy, m.medium);
  vec3 k2x = (m.w + 0.5 * hs * k1w) / o2.r, k2w = o2.gba;
  vec4 o3 = refractiveIndex@((m.x + 0.5 * hs * k2x - m.bmin) * m.invExtent, cauchy, m.medium);
  vec3 k3x = (m.w + 0.5 * hs * k2w) / o3.r, k3w = o3.gba;
  vec4 o4 = refractiveIndex@((m.x + hs * k3x - m.bmin) * m.invExtent, cauchy, m.medium);
  vec3 k4x = (m.w + hs * k3w) / o4.r, k4w = o4.gba;
  m.x += hs / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
  m.w += hs / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
#else
  m.x += hs * (m.w + 0.5 * hs * grad) / m.n;  // Eq. 5.11, w at mid-step
  m.w += hs * grad;                            // Eq. 5.12
#endif
}

// A ray reflected at the interface point p goes on from a tenth of a step back on the side it
// came from (facing: the normal towards that side), if that point is in the ray's material (at a
// thin wall or an edge it may not be: then from p). From p itself a grazing reflected ray met the
// surface again at its next step, within the distance field's interpolation error, and reflected
// again at every step until the step budget ran out.
void stayOnIncidentSide@(inout March@ m, vec3 p, vec3 facing) {
#ifdef HAS_INTERFACES
  vec3 x = p + facing * (0.1 * m.h);
  vec4 d = volumeInterfaces((x - m.bmin) * m.invExtent);
  if (materialAt@(d) == m.medium) {
    m.x = x;
    m.dist = d;
  }
#endif
}

// A ray in a material of constant n whose Cauchy B is not 0 takes a path that depends on λ
// (DISPERSION: red and blue then follow their own rays; raymarch.frag main).
void markDispersed@(inout Ray r, int medium) {
#if defined(HAS_INTERFACES) && defined(CONSTANT_SLOTS)
  if (medium >= 0 && SLOT_DISPERSION[max(medium, 0)] != 0.0) r.dispersed = true;
#endif
}

// Whether the last step changed the material (HAS_INTERFACES): the slot distances at its end, the
// one fetch of most steps.
bool materialChanged@(inout March@ m) {
#ifdef HAS_INTERFACES
  m.dist = volumeInterfaces((m.x - m.bmin) * m.invExtent);
  return materialAt@(m.dist) != m.medium;
#else
  return false;
#endif
}

// The sharp interface the last step crossed (HAS_INTERFACES; materialChanged@): its chord from
// xStepStart to x is cut where the first slot distance that changed sign is zero (linear interpolation, one
// regula falsi refinement), and there, with the normal ∇d of that slot and n on both sides:
// into an opaque material the ray stops and sees its surface (ρE/π); past the critical angle it
// reflects totally; else the exact Fresnel R (corrected Eq. 3.6) splits it between the mirrored
// ray and the one Snell's law bends. The ray goes on from the interface. True when it stopped.
bool crossInterface@(inout Ray r, inout March@ m, float cauchy) {
#ifdef HAS_INTERFACES
  vec3 x0 = m.xStepStart, x1 = m.x;
  vec4 d1 = m.dist;
  int next = materialAt@(d1);
  vec4 d0 = volumeInterfaces((x0 - m.bmin) * m.invExtent);
  // Where each slot's distance changes sign along the chord; then, in order along it, the first
  // surface that changes the material (an outer slot's surface inside an inner one changes nothing).
  vec4 f = vec4(2.0);
  for (int k = 0; k < INTERFACE_SLOTS; ++k) {
    if ((d0[k] < 0.0) == (d1[k] < 0.0)) continue;
    float t = d0[k] / (d0[k] - d1[k]);
    float g = volumeInterfaces((mix(x0, x1, t) - m.bmin) * m.invExtent)[k];
    f[k] = (g < 0.0) == (d0[k] < 0.0) ? t + (1.0 - t) * g / (g - d1[k]) : t * d0[k] / (d0[k] - g);
  }
  float best = 0.0;
  int slot = -1, entered = m.medium;
  for (int pass = 0; pass < INTERFACE_SLOTS; ++pass) {
    int k = -1;
    float nearest = 1.5;  // the earliest crossing not yet looked at
    for (int j = 0; j < INTERFACE_SLOTS; ++j)
      if (f[j] < nearest) { nearest = f[j]; k = j; }
    if (k < 0) break;
    f[k] = 3.0;
    // Just past the surface: a tenth of a voxel on (where two slots share a surface, layers of
    // glass touching, both change sign there, and at the surface the other's sign is noise).
    vec3 beyondX = mix(x0, x1, nearest) + normalize(x1 - x0) * (0.2 * m.h);  // m.h: half a voxel by default
    vec4 dp = volumeInterfaces((beyondX - m.bmin) * m.invExtent);
    dp[k] = (d0[k] < 0.0) ? 1.0 : -1.0;
    int beyond = materialAt@(dp);
    if (beyond != m.medium) {
      slot = k;
      entered = beyond;
      best = nearest;
      break;
    }
  }
  if (slot < 0) {  // on a surface already (the medium disagrees with d0): the crossing is at x0
    best = 0.0;
    slot = m.medium >= 0 ? m.medium : next;
    entered = next;
  }
  markDispersed@(r, entered);  // Fresnel at its surface depends on λ too, whichever way the ray goes
  // The medium from the step's start to the surface (the march gathers no step that crosses one:
  // the part beyond the surface is walked again in the material there).
  gatherMedium@(r, m, (mix(x0, x1, 0.5 * best) - m.bmin) * m.invExtent, best * m.hsLast);
  vec3 p = mix(x0, x1, best);
  m.x = p;
  m.dist = volumeInterfaces((p - m.bmin) * m.invExtent);
  vec3 e = 0.5 / m.invExtent / vec3(textureSize(INTERFACES_SAMPLER, 0));  // half a voxel
  vec3 normal = vec3(
      volumeInterfaces((p + vec3(e.x, 0, 0) - m.bmin) * m.invExtent)[slot] - volumeInterfaces((p - vec3(e.x, 0, 0) - m.bmin) * m.invExtent)[slot],
      volumeInterfaces((p + vec3(0, e.y, 0) - m.bmin) * m.invExtent)[slot] - volumeInterfaces((p - vec3(0, e.y, 0) - m.bmin) * m.invExtent)[slot],
      volumeInterfaces((p + vec3(0, 0, e.z) - m.bmin) * m.invExtent)[slot] - volumeInterfaces((p - vec3(0, 0, e.z) - m.bmin) * m.invExtent)[slot]) / e;
  vec3 uvw = (p - m.bmin) * m.invExtent;
  if (entered >= 0 && SLOT_OPAQUE[entered] > 0.5) {
    vec4 opaque = volumeOpaque(uvw);
    vec3 albedo = opaque.a > 0.0 ? opaque.rgb / opaque.a : vec3(0.8);
    r.radiance += r.T * exp(-m.tau) * opaqueRadiance@(albedo, uvw);
    r.x = (uObjVolToWorld[@] * vec4(p, 1.0)).xyz;
    r.done = true;
    m.stopped = true;
    return true;
  }
  gSurfaceCode = dot(normal, normal) == 0.0 ? 0u : surfaceCode(normalize(normal));
  if (dot(normal, normal) == 0.0) {
    m.medium = entered;
    m.n = refractiveIndex@(uvw, cauchy, entered).r;
    m.w = normalize(m.w) * m.n;
    return false;
  }
  normal = normalize(normal);
  float n1 = refractiveIndex@(uvw, cauchy, m.medium).r, n2 = refractiveIndex@(uvw, cauchy, entered).r;
  vec3 d = normalize(m.w);
  vec3 facing = dot(d, normal) < 0.0 ? normal : -normal;
  float cosI = min(1.0, -dot(d, facing));
  float sin2T = snellSinT2(n1, n2, cosI);
  if (sin2T >= 1.0) {  // total internal reflection
    m.w = reflect(d, facing) * n1;
    m.n = n1;
    stayOnIncidentSide@(m, p, facing);
    return false;
  }
  vec3 refracted = refract(d, facing, n1 / n2);
  vec3 mirrored = reflect(d, facing);
#ifdef FRESNEL
  // One ray goes on: the transmitted one, or the reflected one where it carries more (R > ½, near
  // the critical angle from inside a denser material, so that the light does not vanish there
  // into a near-grazing refracted ray). The other branch is taken as the environment seen in its
  // direction (outside the object exactly; for a reflection inside it, an approximation of the
  // light that would come back through the object).
  float R = fresnelUnpolarised(n1, n2, cosI, sqrt(1.0 - sin2T));
  bool reflects = R > 0.5;
  // The branch not followed, looked up once (llvmpipe would run both calls of an if/else).
  takeBranch@(r, r.T * exp(-m.tau) * (reflects ? 1.0 - R : R), p, reflects ? refracted : mirrored,
              !reflects && m.medium < 0);
  if (reflects) {
    r.T *= R;
    m.w = mirrored * n1;
    m.n = n1;
    stayOnIncidentSide@(m, p, facing);
    return false;
  }
  r.T *= 1.0 - R;
#endif
  m.w = refracted * n2;
  m.n = n2;
  m.medium = entered;
#endif
  return false;
}

// Early termination (not inside a boundary layer, whose reflection is still to come): every
// channel's optical depth past −ln(min transmittance), or the Fresnel factors that low.
bool absorbed@(inout Ray r, inout March@ m) {
  bool opaqueEnough = min(min(m.tau.x, m.tau.y), m.tau.z) > uMaxOpticalDepth || maxComponent(r.T) < uMinTransmittance;
  if (!m.inLayer && opaqueEnough) {
    r.T = vec3(0.0);
    r.done = true;
    m.stopped = true;
    return true;
  }
  return false;
}

// Out of the volume: a layer the ray is still in ends (it stopped inside it, and the reflection
// still counts, or the box ends there, air outside), Beer–Lambert over the object applies, and
// the ray goes back to the world.
void leaveVolume@(inout Ray r, inout March@ m) {
  if (m.inLayer) {
    if (!m.stopped) m.w = renormalised(m.w, 1.0, m.gradPeak);
    crossBoundary@(r, m.nBefore, m.stopped ? m.n : 1.0, m.dBefore, m.gradPeak, m.uvwPeak, r.T * exp(-m.tauBefore));
  }
  if (!m.stopped) r.T *= exp(-m.tau);
  if (m.stopped) return;
  r.x = (uObjVolToWorld[@] * vec4(m.x, 1.0)).xyz;
  r.d = normalize(mat3(uObjVolToWorld[@]) * m.w);
  r.exitX = r.x;
  r.entered = true;
}

// The ray through this object: Eq. 5.10 gathered along the curved ray of Eq. 5.11/5.12. Runs of
// ordinary steps, each run ended by an event (EVENT_*) that is handled after it, outside the step
// loop. A ray that meets more than kMaxEventsPerObject events in one object (light trapped by
// total internal reflection, or a ray caught on a surface) leaves it where it is, as one out of
// steps does.
void march@(inout Ray r, float cauchy) {
#if defined(HAS_DISPERSION) && !defined(CONSTANT_SLOTS)
  r.dispersed = true;  // n(λ) may vary anywhere in the box
#endif
  March@ m = enterVolume@(r, cauchy);
  markDispersed@(r, m.medium);
  if (leftToTheBands(r)) {
    r.done = true;
    return;
  }
  enterSharpFace@(r, m);
  int steps = 0;
  for (int pass = 0; pass < kMaxEventsPerObject && steps < uObjMaxSteps[@]; ++pass) {
    int event = EVENT_NONE;
    for (; steps < uObjMaxSteps[@]; ++steps) {
      if (belowGround@(m)) { event = EVENT_GROUND; break; }
      if (leftActiveRegion@(m)) { event = EVENT_LEFT; break; }
      vec3 uvw = (m.x - m.bmin) * m.invExtent;
      if (skipHomogeneousBrick@(m, uvw)) continue;
      vec4 optics = refractiveIndex@(uvw, cauchy, m.medium);
      m.n = optics.r;
      vec3 grad = optics.gba;
      float grad2 = dot(grad, grad);
      float hs = stepLength@(m, uvw, grad2);
      if (metOpaque@(m, uvw)) { event = EVENT_OPAQUE; break; }
      followBoundaryLayer@(r, m, grad, grad2, grad2 <= m.quiet2, uvw);
      stepRay@(m, grad, hs, cauchy);
      // A step that crossed a surface is gathered up to it only, by crossInterface@.
      if (materialChanged@(m)) { event = EVENT_CROSSING; m.hsLast = hs; break; }
      gatherMedium@(r, m, (0.5 * (m.xStepStart + m.x) - m.bmin) * m.invExtent, hs);  // the step's middle
      if (absorbed@(r, m)) break;
    }
    if (event == EVENT_NONE) break;
    if (event == EVENT_GROUND) {
      if (metGround@(m)) { shadeGround@(r, m); break; }
      continue;  // below the plane beyond the ground, or from below: on
    }
    if (event == EVENT_OPAQUE) { shadeOpaque@(r, m); break; }
    ++steps;  // the step that ended the run, or the one a reflection takes again
    // Out of the box, or on from a total internal reflection at a face on its edge; a surface
    // crossed or reflected at. The way records the event and the material it leaves the ray in.
    bool stop = event == EVENT_LEFT ? !reflectedAtSharpFace@(r, m) : (crossInterface@(r, m, cauchy) || absorbed@(r, m));
    recordWay(r, uint(event));
    recordWay(r, uint(m.medium + 2));
    recordWay(r, gSurfaceCode);
    if (leftToTheBands(r)) {
      r.done = true;
      return;
    }
    if (stop) break;
  }
  leaveVolume@(r, m);
}
