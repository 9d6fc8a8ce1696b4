#pragma once
/// \file
/// Surface materials and the sensor noise model of the thesis (chapter 5.2.2, "Simulating Noise").

#include <intervox/core/error.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/sim/beam_rng.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

namespace intervox::sim {

/// How a surface answers a beam (thesis, chapter 5.2.2, with the reflection model of Material).
enum class Surface : std::uint8_t {
  Diffuse = 0,      ///< the true distance plus Gaussian noise
  Absorbing = 1,    ///< no return, except now and then a diffuse return
  Specular = 2,     ///< a mirror or polished metal: reflects the beam (or, as an option, a random range)
  Transparent = 3,  ///< glass: reflects by Fresnel, else a diffuse return or the beam passes on
};

/// Name of a surface kind ("diffuse", "absorbing", "specular", "transparent").
constexpr std::string_view to_string(Surface s) noexcept {
  switch (s) {
    case Surface::Absorbing:
      return "absorbing";
    case Surface::Specular:
      return "specular";
    case Surface::Transparent:
      return "transparent";
    case Surface::Diffuse:
      break;
  }
  return "diffuse";
}

/// The surface kind named \p name (the inverse of to_string).
/// \throws InvalidArgument naming the unknown name.
inline Surface surface_from_string(std::string_view name) {
  for (Surface s : {Surface::Diffuse, Surface::Absorbing, Surface::Specular, Surface::Transparent})
    if (to_string(s) == name) return s;
  ParamCheck("intervox::sim")
      .fail("unknown surface '" + std::string(name) + "' (diffuse, absorbing, specular, transparent)");
}

/// What a specular surface does with a beam it does not return directly.
enum class SpecularModel : std::uint8_t {
  /// Mirror reflection with exact geometry: the beam is mirrored about the surface normal and
  /// followed to the next surface; the sensor reports the folded path's length (the default).
  Reflect = 0,
  /// The first edition's model: a range drawn uniformly from the sensor's [min_range, max_range],
  /// independent of the geometry (kept so that earlier experiments can be reproduced).
  RandomRange = 1,
};

/// A surface material with the parameters of its noise model.
///
/// For a beam whose path from the sensor to the surface has length d (the range along the
/// original beam; after reflections the whole folded path), and cos θ = |beam · normal| at the
/// surface:
///  - **Diffuse**: returns d + σ(d) · N(0, 1), σ(d) = `sigma` + `sigma_per_metre` · d.
///  - **Absorbing**: with probability `p_return` a diffuse return as above; otherwise the beam
///    ends there with no return (the sensor reports max range: +inf in a depth image, a Beam with
///    hit = false).
///  - **Specular**, `SpecularModel::Reflect` (default): with probability
///    p(θ) = `p_direct` · cos^`lobe_exponent` θ (a Phong-like lobe) the sensor sees the surface
///    itself (a diffuse return); otherwise the beam is reflected, r = b − 2 (b · n) n, and
///    followed on (see sim::trace for the bounce limit). A perfect mirror has p_direct = 0;
///    `polished_metal()` returns mostly within ~10° of normal incidence and rarely beyond ~30°.
///    For a laser striper (a triangulation sensor, LaserStriper::baseline > 0) θ is, along the
///    beam's path before its first reflection, the angle θ_h between the normal n (facing the
///    beam) and the half-vector h = normalize(l + v) of the unit vectors from the surface point
///    towards the laser (l) and towards the striper's camera (v): cos θ_h = max(0, n · h), so the
///    camera sees the line where the normal bisects the two directions (sim::trace_striper; after
///    a reflection the beam angle, the camera assumed to look along the beam's path). Depth
///    cameras and coaxial stripers (baseline 0) use the beam angle.
///    `SpecularModel::RandomRange`: a range drawn uniformly from [min_range, max_range] of the
///    sensor, independent of d (the first edition's model).
///  - **Transparent** (glass): if `fresnel`, the beam is first reflected with Schlick's
///    approximation of the Fresnel reflectance, R(θ) = R0 + (1 − R0)(1 − cos θ)^5 with
///    R0 = ((n − 1)/(n + 1))^2, n = `refractive_index` (0.04 at normal incidence for n = 1.5, 1 at
///    grazing incidence), and a reflected beam behaves as at a mirror. Otherwise (and always
///    without `fresnel`) with probability `p_pass` the beam passes on undeflected to the next
///    surface (the exit face of a transparent solid is a surface too and decides again), else a
///    diffuse return. Refraction does not bend the beam (a thin-sheet approximation), and both
///    faces use the outside angle (no total internal reflection).
/// A returned range is clamped below at the sensor's min_range (never negative); it may exceed
/// max_range slightly through the noise.
///
/// Thread safety: a value type.
struct Material {
  Surface surface = Surface::Diffuse;
  double sigma = 0.01;                                    ///< constant part of the diffuse noise σ [m], >= 0
  double sigma_per_metre = 0.0;                           ///< part of σ proportional to range [m per m], >= 0
  double p_return = 0.05;                                 ///< absorbing: probability of a (diffuse) return, in [0, 1]
  double p_pass = 0.5;                                    ///< transparent: probability of passing through, in [0, 1]
  SpecularModel specular_model = SpecularModel::Reflect;  ///< specular: reflect, or the old random range
  double p_direct = 0.0;          ///< specular: direct-return probability at normal incidence p0, in [0, 1]
  double lobe_exponent = 40.0;    ///< specular: exponent n of cos^n θ, finite and >= 0
  bool fresnel = true;            ///< transparent: reflect by Schlick's Fresnel approximation first
  double refractive_index = 1.5;  ///< transparent: refractive index n for Schlick's R0, finite and >= 1

  /// Default lobe of polished_metal(): p0 = 0.8 and n = 40 give p = 0.80 at 0°, 0.43 at 10°,
  /// 0.066 at 20° and 0.0025 at 30°.
  static constexpr double kPolishedP0 = 0.8;
  static constexpr double kPolishedExponent = 40.0;

  /// A diffuse surface with noise σ = \p sigma + \p sigma_per_metre * range.
  static Material diffuse(double sigma = 0.01, double sigma_per_metre = 0.0) {
    Material m;
    m.surface = Surface::Diffuse;
    m.sigma = sigma;
    m.sigma_per_metre = sigma_per_metre;
    m.validate();
    return m;
  }
  /// An absorbing surface that returns (diffusely) with probability \p p_return.
  static Material absorbing(double p_return = 0.05, double sigma = 0.01) {
    Material m;
    m.surface = Surface::Absorbing;
    m.p_return = p_return;
    m.sigma = sigma;
    m.validate();
    return m;
  }
  /// A perfect mirror: every beam is reflected (p_direct = 0).
  static Material mirror() {
    Material m;
    m.surface = Surface::Specular;
    m.p_direct = 0.0;
    return m;
  }
  /// The specular surface of the current model: a perfect mirror (the same as mirror()).
  static Material specular() { return mirror(); }
  /// Polished metal: a direct (diffuse, σ = \p sigma) return with probability
  /// \p p0 · cos^\p exponent θ, otherwise mirror reflection.
  static Material polished_metal(double p0 = kPolishedP0, double exponent = kPolishedExponent, double sigma = 0.01) {
    Material m;
    m.surface = Surface::Specular;
    m.p_direct = p0;
    m.lobe_exponent = exponent;
    m.sigma = sigma;
    m.validate();
    return m;
  }
  /// The first edition's specular surface: a uniformly random range (SpecularModel::RandomRange).
  static Material specular_random_range() {
    Material m;
    m.surface = Surface::Specular;
    m.specular_model = SpecularModel::RandomRange;
    return m;
  }
  /// Glass that reflects by Fresnel (refractive index \p refractive_index) and otherwise lets a
  /// beam pass with probability \p p_pass.
  static Material transparent(double p_pass = 0.5, double sigma = 0.01, double refractive_index = 1.5) {
    Material m;
    m.surface = Surface::Transparent;
    m.p_pass = p_pass;
    m.sigma = sigma;
    m.refractive_index = refractive_index;
    m.validate();
    return m;
  }
  /// The first edition's transparent surface: no Fresnel reflection, only the pass/return split.
  static Material transparent_without_fresnel(double p_pass = 0.5, double sigma = 0.01) {
    Material m = transparent(p_pass, sigma);
    m.fresnel = false;
    return m;
  }
  /// The default material of each kind (Specular: mirror(); Transparent: transparent()).
  static Material of(Surface s) {
    switch (s) {
      case Surface::Absorbing:
        return absorbing();
      case Surface::Specular:
        return specular();
      case Surface::Transparent:
        return transparent();
      case Surface::Diffuse:
        break;
    }
    return diffuse();
  }

  /// \throws InvalidArgument for a negative or non-finite σ, a probability outside [0, 1], a
  /// negative or non-finite lobe exponent, a refractive index below 1 or not finite, or an
  /// unknown surface kind or specular model.
  void validate() const {
    const ParamCheck check("intervox::sim::Material");
    if (static_cast<int>(surface) > 3) check.fail("unknown surface kind");
    if (static_cast<int>(specular_model) > 1) check.fail("unknown specular model");
    check.nonnegative("sigma", sigma);
    check.nonnegative("sigma_per_metre", sigma_per_metre);
    check.in_range("p_return", p_return, 0, 1);
    check.in_range("p_pass", p_pass, 0, 1);
    check.in_range("p_direct", p_direct, 0, 1);
    check.nonnegative("lobe_exponent", lobe_exponent);
    check.at_least("refractive_index", refractive_index, 1.0);
  }

  /// The diffuse noise σ at range \p d.
  double sigma_at(double d) const noexcept { return sigma + sigma_per_metre * d; }

  /// Specular: the probability of a direct return at cos θ = \p cos_theta (p_direct · cos^n θ;
  /// 0 for every other surface and for SpecularModel::RandomRange).
  double direct_return_probability(double cos_theta) const noexcept {
    if (surface != Surface::Specular || specular_model != SpecularModel::Reflect || p_direct <= 0) return 0.0;
    return p_direct * std::pow(std::clamp(std::abs(cos_theta), 0.0, 1.0), lobe_exponent);
  }

  /// Transparent with fresnel: Schlick's reflectance at cos θ = \p cos_theta (0 otherwise).
  double fresnel_reflectance(double cos_theta) const noexcept {
    if (surface != Surface::Transparent || !fresnel) return 0.0;
    const double r0 =
        (refractive_index - 1) * (refractive_index - 1) / ((refractive_index + 1) * (refractive_index + 1));
    const double c = 1.0 - std::clamp(std::abs(cos_theta), 0.0, 1.0);
    return r0 + (1.0 - r0) * c * c * c * c * c;
  }

  /// True if the response depends on the angle of incidence (the caller then needs the normal).
  bool needs_normal() const noexcept {
    return (surface == Surface::Specular && specular_model == SpecularModel::Reflect) ||
           (surface == Surface::Transparent && fresnel);
  }
};

/// The material named \p name, for command lines: "diffuse", "absorbing", "specular" (= "mirror"),
/// "polished-metal", "transparent" (= "glass"), and the first edition's "specular-random" and
/// "transparent-no-fresnel"; each with its default parameters.
/// \throws InvalidArgument naming the unknown name and the known ones.
inline Material material_from_string(std::string_view name) {
  if (name == "diffuse") return Material::diffuse();
  if (name == "absorbing") return Material::absorbing();
  if (name == "specular" || name == "mirror") return Material::mirror();
  if (name == "polished-metal") return Material::polished_metal();
  if (name == "transparent" || name == "glass") return Material::transparent();
  if (name == "specular-random") return Material::specular_random_range();
  if (name == "transparent-no-fresnel") return Material::transparent_without_fresnel();
  ParamCheck("intervox::sim")
      .fail("unknown material '" + std::string(name) +
            "' (diffuse, absorbing, specular, mirror, polished-metal, transparent, glass, "
            "specular-random, transparent-no-fresnel)");
}

/// The material names material_from_string() accepts.
inline constexpr std::string_view kMaterialNames[] = {"diffuse", "absorbing",       "specular",
                                                      "mirror",  "polished-metal",  "transparent",
                                                      "glass",   "specular-random", "transparent-no-fresnel"};

/// What one surface encounter yields.
enum class Response : std::uint8_t {
  Return = 0,    ///< the sensor measures a range (given separately)
  NoReturn = 1,  ///< the beam is lost (absorbed): the sensor reports max range
  Pass = 2,      ///< the beam continues undeflected to the next surface
  Reflect = 3,   ///< the beam is mirrored about the surface normal and continues
};

/// Applies the noise model of \p m to one surface encounter at path length \p d and angle
/// cos θ = \p cos_theta (ignored unless m.needs_normal()), drawing from \p rng; on Return writes
/// the measured range to \p range. \p min_range and \p max_range are the sensor's limits (for the
/// random-range model and the clamp). Draws happen in a fixed order per surface kind, so a
/// beam's stream gives the same result wherever it is evaluated.
inline Response respond(const Material& m, double d, double cos_theta, double min_range, double max_range, BeamRng& rng,
                        double& range) noexcept {
  const auto diffuse = [&] {
    range = std::max(min_range, d + m.sigma_at(d) * rng.normal());
    return Response::Return;
  };
  switch (m.surface) {
    case Surface::Diffuse:
      return diffuse();
    case Surface::Absorbing:
      if (rng.bernoulli(m.p_return)) return diffuse();
      return Response::NoReturn;
    case Surface::Specular:
      if (m.specular_model == SpecularModel::RandomRange) {
        range = rng.uniform(min_range, max_range);
        return Response::Return;
      }
      if (m.p_direct > 0 && rng.bernoulli(m.direct_return_probability(cos_theta))) return diffuse();
      return Response::Reflect;
    case Surface::Transparent:
      if (m.fresnel && rng.bernoulli(m.fresnel_reflectance(cos_theta))) return Response::Reflect;
      if (rng.bernoulli(m.p_pass)) return Response::Pass;
      return diffuse();
  }
  return Response::NoReturn;
}

/// A direct (diffuse) return of \p m at path length \p d: writes d + σ(d) · N(0, 1), clamped
/// below at \p min_range, to \p range and returns Response::Return, drawing one normal from
/// \p rng (the draws of respond()'s diffuse return). The simulator's near-normal glint
/// (SimOptions::glint) answers with it in place of respond() for any surface kind.
inline Response respond_direct(const Material& m, double d, double min_range, BeamRng& rng, double& range) noexcept {
  range = std::max(min_range, d + m.sigma_at(d) * rng.normal());
  return Response::Return;
}

}  // namespace intervox::sim
