// Parsing of material overrides: `--material KEY=VALUE[,KEY=VALUE...]` (docs/programs.md), and the
// small KEY=VALUE helpers that procedural shape specs (`procedural:NAME,key=value`) share with it.
//
// Keys (values are per world unit where they are coefficients):
//   ior=N          refractive index n at λ_d (≥ 1); `n` is accepted as a synonym
//   sigma_a=R:G:B  absorption coefficient σa (≥ 0; one value means grey)
//   emission=R:G:B emitted radiance L_e (≥ 0)
//   albedo=R:G:B   diffuse albedo in [0, 1]; makes the material an opaque embedding/receiver
//   scatter=W      scatter strength (albedo) ω̂ in [0, 1] (thesis Eq. 3.5)
//   g=G            Henyey–Greenstein anisotropy in (−1, 1)
//   abbe=V         Abbe number V_d > 0; sets the Cauchy B = 0.523655·(n − 1)/V_d (docs/volume-format.md)
//   name=TEXT      name shown in messages and --stats
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "voxelize/material.h"

namespace eik {

using KeyValue = std::pair<std::string, std::string>;

// Splits "k1=v1,k2=v2" into pairs (whitespace around keys and values trimmed). An empty spec gives
// no pairs. Throws InputError naming `source` for an item without '=', an empty key or a key given
// twice.
std::vector<KeyValue> splitKeyValues(const std::string& spec, const std::string& source);

// A finite number, or InputError "SOURCE: KEY: 'TEXT' is not a number".
double parseNumber(const std::string& text, const std::string& source, const std::string& key);
// "R:G:B" or a single value for all three channels.
glm::dvec3 parseTriple(const std::string& text, const std::string& source, const std::string& key);

// How numbers and lists of keys appear in messages: "1.5" (ostream default format), "a, b, c".
std::string formatValue(double value);
std::string joinedList(const std::vector<std::string>& items);

// The keys parseMaterialSpec accepts, in documentation order ("ior", "n", "sigma_a", ...).
const std::vector<std::string>& materialKeys();
bool isMaterialKey(std::string_view key);

// Applies already split material keys to `base`. Every key must be a material key. `abbe` is
// applied after all other keys, so `abbe=40,ior=1.7` and `ior=1.7,abbe=40` agree.
Material applyMaterialOverrides(const std::vector<KeyValue>& pairs, Material base, const std::string& source);

// Parses a `--material` value. `source` names the flag (or file) in error messages, e.g.
// "--material: g: 1.2 is outside (-1, 1)".
Material parseMaterialSpec(const std::string& spec, Material base, const std::string& source = "--material");

}  // namespace eik
