// One object's ray march (thesis §6.3, Eq. 5.10–5.12), instantiated once per object of the scene
// by SceneRenderer: every '@' becomes the object's index, and the object's volume layout
// (gl::VolumeTextureLayout::glslDefines with its own sampler names uO@Tex0...) is #defined around
// it, so each object samples its own textures with no branches on uniforms (DESIGN §3; GLSL 3.30
// cannot index sampler arrays with a variable). Included by nothing: raymarch.frag's
// "// @OBJECTS@" line is replaced with the instances.
//
// The ray is carried into the volume's own space (§6.3.1: x' = M⁻¹x; ∇n' = M⁻ᵀ∇n is the stored
// field itself there), marched with arc length s through the box of the non-trivial region, and
// carried back to the world when it leaves.

// Radiance of an opaque embedding of diffuse albedo ρ at uvw: ρE/π with the baked irradiance E,
// plus the unoccluded environment.
vec3 opaqueRadiance@(vec3 albedo, vec3 uvw) {
#ifdef HAS_IRRADIANCE
  return albedo * (texture(IRRADIANCE_SAMPLER, uvw).IRRADIANCE_SWZ * INV_PI + uAmbientRadiance);
#else
  return albedo * uAmbientRadiance;
#endif
}

// The baked irradiance on the ground at world point xw, if it lies inside this volume: E on the
// ground = irradiance · max(0, N·(−l)) with the baked light direction l (thesis §3.2.2). Returns
// the weight of the bake against the unoccluded light: 0 outside the box, rising to 1 over the
// outer kGroundBlendVoxels, so the edge of the baked region leaves no seam.
#ifdef GROUND
float bakedGroundIrradiance@(vec3 xw, out vec3 E) {
  E = vec3(0.0);
#if defined(HAS_IRRADIANCE) && defined(HAS_LIGHT_DIR)
  vec3 x = (uObjWorldToVol[@] * vec4(xw, 1.0)).xyz;
  vec3 uvw = (x - uObjBoundsMin[@]) / (uObjBoundsMax[@] - uObjBoundsMin[@]);
  // Distance to each face, in voxels, past the outermost voxel centres (half a voxel in).
  vec3 fromFace = min(uvw, 1.0 - uvw) / (2.0 * uObjHalfVoxel[@]) - 0.5;
  if (min(min(fromFace.x, fromFace.y), fromFace.z) <= 0.0) return 0.0;
  vec3 normal = normalize(mat3(uObjWorldToVol[@]) * uGroundNormal);
  vec3 l = texture(LIGHT_DIR_SAMPLER, uvw).LIGHT_DIR_SWZ;
  E = texture(IRRADIANCE_SAMPLER, uvw).IRRADIANCE_SWZ * max(0.0, -dot(normal, l));
  // The same distances measured within the ground plane: a face parallel to the ground never
  // meets it (a box's floor just under the ground must not fade the bake).
  vec3 inPlane = fromFace / max(sqrt(max(1.0 - normal * normal, 0.0)), 1e-3);
  return clamp(min(min(inPlane.x, inPlane.y), inPlane.z) / kGroundBlendVoxels, 0.0, 1.0);
#else
  return 0.0;
#endif
}
#endif

// n and ∇n at uvw for the wavelength whose Cauchy term (1/λ² − 1/λ_d²) is `cauchy` (DESIGN §4.1):
// n(λ) = n + B·cauchy; ∇n scales with n − 1 (B ∝ n − 1 within one material).
vec4 refractiveIndex@(vec3 uvw, float cauchy) {
  vec4 optics = texture(IOR_SAMPLER, uvw);  // ior (r), ior_grad (gba): one fetch
#if defined(DISPERSION) && defined(HAS_DISPERSION)
  float B = texture(DISPERSION_SAMPLER, uvw).DISPERSION_SWZ;
  optics.gba *= 1.0 + cauchy * B / max(optics.r - 1.0, 1e-3);
  optics.r += B * cauchy;
#endif
#ifdef NO_REFRACTION
  optics.gba = vec3(0.0);
#endif
  return optics;
}

#ifdef FRESNEL
// δ·R·L_r and the transmission factor (Eq. 5.10, DESIGN §5), once the ray has crossed a boundary
// layer: n1 before it, n2 after it, the incident direction dIn (volume space) and the normal where
// |∇n| peaked; TBefore is the transmittance the ray had before the layer.
void crossBoundary@(inout Ray r, float n1, float n2, vec3 dIn, vec3 gradPeak, vec3 uvwPeak, vec3 TBefore) {
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
    vec3 tint = vec3(1.0);
#ifdef HAS_REFLECT
    vec4 reflectTint = texture(REFLECT_SAMPLER, uvwPeak).REFLECT_SWZ;
    tint = mix(vec3(1.0), reflectTint.rgb, clamp(reflectTint.a, 0.0, 1.0));
#endif
    vec3 reflected = normalize(mat3(uObjVolToWorld[@]) * reflect(dIn, normal));
    r.radiance += TBefore * R * tint * environmentRadiance(reflected, uReflectionLod);
  }
}
#endif

void march@(inout Ray r, float cauchy) {
  mat4 toVolume = uObjWorldToVol[@];
  vec3 bmin = uObjBoundsMin[@];
  vec3 invExtent = 1.0 / (uObjBoundsMax[@] - bmin);
  vec3 amin = uObjActiveMin[@];
  vec3 amax = uObjActiveMax[@];
  float h = uObjStep[@];
  vec3 d = normalize(mat3(toVolume) * r.d);
  vec3 x = (toVolume * vec4(r.x, 1.0)).xyz + d * (1e-3 * h);  // a hair inside the box
  vec4 optics = refractiveIndex@((x - bmin) * invExtent, cauchy);
  float n = optics.r;
  vec3 w = d * n;  // |w| = n along an exact ray (DESIGN §5)
#ifdef SHARP_FACES
  // The material touches the box's faces (SceneRenderer found n ≠ 1 there): where the ray enters
  // through such a face, the face is a sharp interface — Snell's law and Fresnel, exactly.
  vec3 extent = uObjBoundsMax[@] - bmin;
  vec3 rel = (x - bmin) * invExtent;
  vec3 toFace = min(rel, 1.0 - rel) * extent;
  float nearest = min(min(toFace.x, toFace.y), toFace.z);
  if (abs(n - 1.0) > 1e-3 && nearest < 0.01 * h) {
    vec3 outward = vec3(equal(toFace, vec3(nearest))) * sign(rel - 0.5);
    outward = normalize(outward);
#ifdef FRESNEL
    float R = fresnelReflectance(1.0, n, abs(dot(d, outward)));
    r.radiance += r.T * R * environmentRadiance(normalize(mat3(uObjVolToWorld[@]) * reflect(d, outward)), uReflectionLod);
    r.T *= 1.0 - R;
#endif
    d = refract(d, outward, 1.0 / n);
    w = d * n;
  }
  vec3 xStepStart = x;
#endif
#ifdef GROUND
  vec3 groundPoint = (toVolume * vec4(uGroundPoint, 1.0)).xyz;
  vec3 groundNormal = normalize(mat3(toVolume) * uGroundNormal);
  float side = dot(x - groundPoint, groundNormal);
  vec3 xPrev = x;
#endif
  // The boundary layer the ray is in: it begins where |∇n| exceeds the threshold and ends where
  // |∇n| falls below a 16th of it (quiet). Where it ends, |w| is set back to n along the layer's
  // normal (the gradient where it peaked), keeping the component across it: n·sin θ, Snell's law.
  // Elsewhere |w| = n holds by itself (w changes only where ∇n ≠ 0), so the steps do not
  // renormalise (llvmpipe: it was half the cost of a step).
  bool inLayer = false;
  float gradPeak2 = 0.0;
  vec3 gradPeak = vec3(0.0);
  float threshold2 = uObjBoundaryGrad[@] * uObjBoundaryGrad[@];
  float quiet2 = threshold2 * (1.0 / 256.0);
#ifdef FRESNEL
  // The state at the last quiet sample before the layer: n, direction, optical depth.
  float nBefore = n;
  vec3 dBefore = d, tauBefore = vec3(0.0), uvwPeak = vec3(0.0);
#endif
  vec3 tau = vec3(0.0);  // optical depth ∫σa ds in this object (Beer–Lambert: T = exp(−τ))
  vec3 absorbingMin = uObjAbsorbingMin[@];
  vec3 absorbingMax = uObjAbsorbingMax[@];
  bool stopped = false;
  for (int i = 0; i < uObjMaxSteps[@]; ++i) {
#ifdef GROUND
    // The ground inside the volume: the step crossed it from above (checked before leaving the
    // box, as the last step may do both).
    float s = dot(x - groundPoint, groundNormal);
    if (side > 0.0 && s <= 0.0) {
      vec3 hit = mix(xPrev, x, side / (side - s));
      vec3 hitWorld = (uObjVolToWorld[@] * vec4(hit, 1.0)).xyz;
      if (onGround(hitWorld)) {
        r.radiance += r.T * exp(-tau) * groundRadiance(hitWorld);
        r.x = hitWorld;
        r.done = true;
        stopped = true;
        break;
      }
    }
    side = s;
    xPrev = x;
#endif
    if (any(lessThan(x, amin)) || any(greaterThan(x, amax))) {  // left the non-trivial region
#ifdef SHARP_FACES
      // Leaving through a face the material touches: refraction out by Snell's law, or total
      // internal reflection back in (the step is taken again, reflected).
      if (n > 1.0 + 1e-3 && (any(lessThan(x, bmin)) || any(greaterThan(x, uObjBoundsMax[@])))) {
        vec3 outward = normalize(step(uObjBoundsMax[@], x) - step(x, bmin));
        vec3 dir = normalize(w);
        // Back onto the face the step crossed (the first one along the step).
        vec3 face = mix(bmin, uObjBoundsMax[@], step(0.0, outward));
        vec3 along = (face - xStepStart) / (x - xStepStart);
        along = mix(vec3(1.0), along, abs(outward));
        x = mix(xStepStart, x, clamp(min(min(along.x, along.y), along.z), 0.0, 1.0));
        float R = fresnelReflectance(n, 1.0, dot(dir, outward));
        if (R >= 1.0) {
          w = reflect(w, outward);
          x = xStepStart;
          continue;
        }
#ifdef FRESNEL
        r.T *= 1.0 - R;
#endif
        w = refract(dir, -outward, n);
      }
#endif
      break;
    }
    vec3 uvw = (x - bmin) * invExtent;
#ifdef SKIP_HOMOGENEOUS
    // A homogeneous brick (SceneRenderer: n constant, no ∇n, constant σa, nothing else, around it
    // too): the ray is straight there, so it crosses the brick in one step.
    if (texture(uO@Bricks, uvw).r > 0.5) {
      vec3 dir = normalize(w);
      vec3 brickSize = uObjBrickSize[@];
      vec3 brickLo = bmin + floor((x - bmin) / brickSize) * brickSize;
      // Distance to the brick's exit face; axes the ray runs parallel to never end it.
      vec3 toFace = abs(mix(brickLo, brickLo + brickSize, step(0.0, dir)) - x) / max(abs(dir), vec3(1e-12));
      toFace = mix(vec3(1e30), toFace, greaterThan(abs(dir), vec3(1e-8)));
      float L = min(min(toFace.x, toFace.y), toFace.z) + 0.01 * h;
#ifdef FRESNEL
      if (!inLayer) {  // a quiet stretch: the state before any boundary ahead
        nBefore = length(w);
        dBefore = dir;
        tauBefore = tau;
      }
#endif
#if defined(ATTENUATION) && defined(HAS_SIGMA_A)
      tau += texture(SIGMA_A_SAMPLER, uvw).SIGMA_A_SWZ * L;  // Beer–Lambert, σa constant here
#endif
      x += dir * L;
      continue;
    }
#endif
    optics = refractiveIndex@(uvw, cauchy);
    n = optics.r;
    vec3 grad = optics.gba;
    // Far from any boundary (|∇n| under a 16th of the boundary threshold) the step doubles: the
    // next boundary layer is still resolved, and the renormalisation across ∇n keeps the direction
    // after it exact (Snell's law in a layered medium).
    float grad2 = dot(grad, grad);
    bool quiet = grad2 <= quiet2;
    float hs = quiet ? 2.0 * h : h;
#ifdef HAS_OPAQUE
    vec4 opaque = texture(OPAQUE_SAMPLER, uvw).OPAQUE_SWZ;
    if (opaque.a > 0.5) {  // an opaque embedding stops the ray
      // The albedo interpolated with the indicator, divided by it (premultiplied at the edge).
      r.radiance += r.T * exp(-tau) * opaqueRadiance@(opaque.rgb / opaque.a, uvw);
      r.x = (uObjVolToWorld[@] * vec4(x, 1.0)).xyz;
      r.done = true;
      stopped = true;
      break;
    }
#endif
#ifdef FRESNEL
    // n, the direction and T before a layer are those of its last quiet sample, so the smoothed
    // tails do not bias R (at 80° a 0.5 % error in n·cos θ is 2 % in R).
    if (!inLayer && quiet) {
      nBefore = n;
      dBefore = normalize(w);
      tauBefore = tau;
    }
#endif
    if (inLayer ? !quiet : grad2 > threshold2) {
      if (!inLayer || grad2 > gradPeak2) {
        gradPeak = grad;
        gradPeak2 = grad2;
#ifdef FRESNEL
        uvwPeak = uvw;
#endif
      }
      inLayer = true;
    } else if (inLayer) {
      inLayer = false;
      w = renormalised(w, n, gradPeak);
#ifdef FRESNEL
      // δ·R·L_r and the transmission T (Eq. 5.10, DESIGN §5), with n before and after the layer.
      crossBoundary@(r, nBefore, n, dBefore, gradPeak, uvwPeak, r.T * exp(-tauBefore));
#endif
    }
#if defined(ATTENUATION) && defined(HAS_SIGMA_A)
    // Beer–Lambert, per channel: T = exp(−τ). σa is fetched only inside the box where it is not 0.
    if (all(greaterThanEqual(x, absorbingMin)) && all(lessThanEqual(x, absorbingMax)))
      tau += texture(SIGMA_A_SAMPLER, uvw).SIGMA_A_SWZ * hs;
#endif
#if defined(EMISSION) && defined(HAS_EMISSION)
    r.radiance += r.T * exp(-tau) * texture(EMISSION_SAMPLER, uvw).EMISSION_SWZ * hs;  // L_e
#endif
#if defined(SCATTERING) && defined(HAS_SCATTER) && defined(HAS_IRRADIANCE) && defined(HAS_LIGHT_DIR)
    // ω̂·L_s: the baked irradiance scattered towards the eye by Henyey–Greenstein (Eq. 5.10).
    vec2 scatter = texture(SCATTER_SAMPLER, uvw).SCATTER_SWZ;
    if (scatter.x > 0.0) {
      vec3 l = texture(LIGHT_DIR_SAMPLER, uvw).LIGHT_DIR_SWZ;
      float cosTheta = dot(l, -normalize(w));
      r.radiance += r.T * exp(-tau) * scatter.x * henyeyGreenstein(scatter.y, cosTheta) *
                    texture(IRRADIANCE_SAMPLER, uvw).IRRADIANCE_SWZ * hs;
    }
#endif
    // One step of the ray equation in arc length (Eq. 5.11/5.12): dx/ds = w/n, dw/ds = ∇n.
#ifdef SHARP_FACES
    xStepStart = x;
#endif
#ifdef RK4
    vec3 k1x = w / n, k1w = grad;
    vec4 o2 = refractiveIndex@((x + 0.5 * hs * k1x - bmin) * invExtent, cauchy);
    vec3 k2x = (w + 0.5 * hs * k1w) / o2.r, k2w = o2.gba;
    vec4 o3 = refractiveIndex@((x + 0.5 * hs * k2x - bmin) * invExtent, cauchy);
    vec3 k3x = (w + 0.5 * hs * k2w) / o3.r, k3w = o3.gba;
    vec4 o4 = refractiveIndex@((x + hs * k3x - bmin) * invExtent, cauchy);
    vec3 k4x = (w + hs * k3w) / o4.r, k4w = o4.gba;
    x += hs / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
    w += hs / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
#else
    x += hs * (w + 0.5 * hs * grad) / n;  // the position with the mid-step w (second order in the drift)
    w += hs * grad;
#endif
    // Early termination (not inside a boundary layer, whose reflection is still to come): every
    // channel's optical depth past −ln(min transmittance), or the Fresnel factors that low.
    bool opaqueEnough = min(min(tau.x, tau.y), tau.z) > uMaxOpticalDepth || maxComponent(r.T) < uMinTransmittance;
    if (!inLayer && opaqueEnough) {
      r.T = vec3(0.0);
      r.done = true;
      stopped = true;
      break;
    }
  }
  // A layer the ray is still in: it stopped inside it (the reflection still counts), or the box
  // ends there (air outside).
  if (inLayer) {
    if (!stopped) w = renormalised(w, 1.0, gradPeak);
#ifdef FRESNEL
    crossBoundary@(r, nBefore, stopped ? n : 1.0, dBefore, gradPeak, uvwPeak, r.T * exp(-tauBefore));
#endif
  }
  if (!stopped) r.T *= exp(-tau);
  if (stopped) return;
  r.x = (uObjVolToWorld[@] * vec4(x, 1.0)).xyz;
  r.d = normalize(mat3(uObjVolToWorld[@]) * w);
  r.exitX = r.x;
  r.entered = true;
}
