// Sampling a volume uploaded by gl::VolumeTextures. Needs the #defines of
// VolumeTextureLayout::glslDefines() (pass them as the prelude of ShaderLibrary::source) and
// declares the samplers uVolumeTex0..N-1 that VolumeTextures::bind() sets.
// `uvw` is the texture coordinate: voxel (i,j,k) sits at ((i,j,k) + 0.5) / dims.
// A field the volume lacks returns its neutral value (n = 1, zero elsewhere) at no cost.
// The viewer, which samples several volumes in one shader, puts a copy of this file in each
// object's scope with the samplers and functions renamed by #defines (viewer/raymarch_shader.h).
#ifndef VOLUME_TEXTURE_COUNT
#error "common/volume.glsl needs the defines of gl::VolumeTextureLayout::glslDefines()"
#endif

#if VOLUME_TEXTURE_COUNT > 0
uniform sampler3D uVolumeTex0;
#endif
#if VOLUME_TEXTURE_COUNT > 1
uniform sampler3D uVolumeTex1;
#endif
#if VOLUME_TEXTURE_COUNT > 2
uniform sampler3D uVolumeTex2;
#endif
#if VOLUME_TEXTURE_COUNT > 3
uniform sampler3D uVolumeTex3;
#endif
#if VOLUME_TEXTURE_COUNT > 4
uniform sampler3D uVolumeTex4;
#endif
#if VOLUME_TEXTURE_COUNT > 5
uniform sampler3D uVolumeTex5;
#endif
#if VOLUME_TEXTURE_COUNT > 6
uniform sampler3D uVolumeTex6;
#endif
#if VOLUME_TEXTURE_COUNT > 7
uniform sampler3D uVolumeTex7;
#endif
#if VOLUME_TEXTURE_COUNT > 8
uniform sampler3D uVolumeTex8;
#endif

float volumeIor(vec3 uvw) {
#ifdef HAS_IOR
  return texture(IOR_SAMPLER, uvw).IOR_SWZ;
#else
  return 1.0;
#endif
}

vec3 volumeIorGrad(vec3 uvw) {
#ifdef HAS_IOR_GRAD
  return texture(IOR_GRAD_SAMPLER, uvw).IOR_GRAD_SWZ;
#else
  return vec3(0.0);
#endif
}

vec3 volumeSigmaA(vec3 uvw) {
#ifdef HAS_SIGMA_A
  return texture(SIGMA_A_SAMPLER, uvw).SIGMA_A_SWZ;
#else
  return vec3(0.0);
#endif
}

float volumeDispersion(vec3 uvw) {
#ifdef HAS_DISPERSION
  return texture(DISPERSION_SAMPLER, uvw).DISPERSION_SWZ;
#else
  return 0.0;
#endif
}

vec3 volumeEmission(vec3 uvw) {
#ifdef HAS_EMISSION
  return texture(EMISSION_SAMPLER, uvw).EMISSION_SWZ;
#else
  return vec3(0.0);
#endif
}

// x: albedo ω̂, y: Henyey–Greenstein g.
vec2 volumeScatter(vec3 uvw) {
#ifdef HAS_SCATTER
  return texture(SCATTER_SAMPLER, uvw).SCATTER_SWZ;
#else
  return vec2(0.0);
#endif
}

vec3 volumeIrradiance(vec3 uvw) {
#ifdef HAS_IRRADIANCE
  return texture(IRRADIANCE_SAMPLER, uvw).IRRADIANCE_SWZ;
#else
  return vec3(0.0);
#endif
}

vec3 volumeLightDir(vec3 uvw) {
#ifdef HAS_LIGHT_DIR
  return texture(LIGHT_DIR_SAMPLER, uvw).LIGHT_DIR_SWZ;
#else
  return vec3(0.0);
#endif
}

// rgb: diffuse albedo, a: indicator.
vec4 volumeOpaque(vec3 uvw) {
#ifdef HAS_OPAQUE
  return texture(OPAQUE_SAMPLER, uvw).OPAQUE_SWZ;
#else
  return vec4(0.0);
#endif
}

// rgb: reflection tint, a: weight.
vec4 volumeReflect(vec3 uvw) {
#ifdef HAS_REFLECT
  return texture(REFLECT_SAMPLER, uvw).REFLECT_SWZ;
#else
  return vec4(0.0);
#endif
}

// The signed distances of the interface slots (core/interfaces.h): negative inside; +band far out.
vec4 volumeInterfaces(vec3 uvw) {
#if defined(HAS_INTERFACES) && defined(INTERFACES_UNUSED)
  // The used slots' distances alone were uploaded (R or RG): the others read their one constant.
  vec4 d = vec4(INTERFACES_UNUSED);
  d.INTERFACES_SWZ = texture(INTERFACES_SAMPLER, uvw).INTERFACES_SWZ;
  return d;
#elif defined(HAS_INTERFACES)
  return texture(INTERFACES_SAMPLER, uvw).INTERFACES_SWZ;
#else
  return vec4(1e30);
#endif
}
