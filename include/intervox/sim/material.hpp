#pragma once
/// \file
/// Surface materials and the sensor noise model of the thesis (chapter 5.2.2, "Simulating Noise").

#include <intervox/core/error.hpp>
#include <intervox/sim/random.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

namespace intervox::sim {

/// How a surface answers a beam (thesis, chapter 5.2.2).
enum class Surface : std::uint8_t {
  Diffuse = 0,      ///< the true distance plus Gaussian noise
  Absorbing = 1,    ///< no return, except now and then a diffuse return
  Specular = 2,     ///< an entirely random distance along the beam
  Transparent = 3,  ///< randomly a diffuse return, or the beam passes on to the next surface
};

/// Name of a surface kind ("diffuse", "absorbing", "specular", "transparent").
constexpr std::string_view to_string(Surface s) noexcept {
  switch (s) {
    case Surface::Absorbing: return "absorbing";
    case Surface::Specular: return "specular";
    case Surface::Transparent: return "transparent";
    case Surface::Diffuse: break;
  }
  return "diffuse";
}

/// The surface kind named \p name (the inverse of to_string).
/// \throws InvalidArgument naming the unknown name.
inline Surface surface_from_string(std::string_view name) {
  for (Surface s : {Surface::Diffuse, Surface::Absorbing, Surface::Specular, Surface::Transparent})
    if (to_string(s) == name) return s;
  throw InvalidArgument("intervox::sim: unknown surface '" + std::string(name) +
                        "' (diffuse, absorbing, specular, transparent)");
}

/// A surface material with the parameters of its noise model.
///
/// For a beam whose true range (distance along the beam from the sensor) to the surface is d:
///  - **Diffuse**: returns d + sigma(d) * N(0, 1), sigma(d) = `sigma` + `sigma_per_metre` * d.
///  - **Absorbing**: with probability `p_return` a diffuse return as above; otherwise the beam
///    ends there with no return (the sensor reports max range: +inf in a depth image, a Beam with
///    hit = false).
///  - **Specular**: returns a range drawn uniformly from [min_range, max_range] of the sensor,
///    independent of d (the beam was reflected elsewhere; "an entirely random value").
///  - **Transparent**: with probability `p_pass` the beam passes and is followed to the next
///    surface (the exit face of a transparent solid is a surface too and decides again);
///    otherwise a diffuse return.
/// A returned range is clamped below at the sensor's min_range (never negative); it may exceed
/// max_range slightly through the noise.
///
/// Thread safety: a value type.
struct Material {
  Surface surface = Surface::Diffuse;
  double sigma = 0.01;           ///< constant part of the diffuse noise σ [m], >= 0
  double sigma_per_metre = 0.0;  ///< part of σ proportional to range [m per m], >= 0
  double p_return = 0.05;        ///< absorbing: probability of a (diffuse) return, in [0, 1]
  double p_pass = 0.5;           ///< transparent: probability of passing through, in [0, 1]

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
  /// A specular (mirror-like, reflecting metal) surface: a uniformly random range.
  static Material specular() {
    Material m;
    m.surface = Surface::Specular;
    return m;
  }
  /// A transparent surface that lets a beam pass with probability \p p_pass.
  static Material transparent(double p_pass = 0.5, double sigma = 0.01) {
    Material m;
    m.surface = Surface::Transparent;
    m.p_pass = p_pass;
    m.sigma = sigma;
    m.validate();
    return m;
  }
  /// The default material of each kind.
  static Material of(Surface s) {
    switch (s) {
      case Surface::Absorbing: return absorbing();
      case Surface::Specular: return specular();
      case Surface::Transparent: return transparent();
      case Surface::Diffuse: break;
    }
    return diffuse();
  }

  /// \throws InvalidArgument for a negative or non-finite σ, a probability outside [0, 1], or
  /// an unknown surface kind.
  void validate() const {
    if (static_cast<int>(surface) > 3) throw InvalidArgument("intervox::sim::Material: unknown surface kind");
    if (!(std::isfinite(sigma) && sigma >= 0) || !(std::isfinite(sigma_per_metre) && sigma_per_metre >= 0))
      throw InvalidArgument("intervox::sim::Material: sigma and sigma_per_metre must be finite and >= 0");
    if (!(p_return >= 0 && p_return <= 1)) throw InvalidArgument("intervox::sim::Material: p_return must lie in [0, 1]");
    if (!(p_pass >= 0 && p_pass <= 1)) throw InvalidArgument("intervox::sim::Material: p_pass must lie in [0, 1]");
  }

  /// The diffuse noise σ at range \p d.
  double sigma_at(double d) const noexcept { return sigma + sigma_per_metre * d; }
};

/// What one surface encounter yields.
enum class Response : std::uint8_t {
  Return = 0,  ///< the sensor measures a range (given separately)
  NoReturn = 1,  ///< the beam is lost (absorbed): the sensor reports max range
  Pass = 2,    ///< the beam continues to the next surface
};

/// Applies the noise model of \p m to one surface encounter at true range \p d, drawing from
/// \p rng; on Return writes the measured range to \p range. \p min_range and \p max_range are the
/// sensor's limits (for the specular model and the clamp).
inline Response respond(const Material& m, double d, double min_range, double max_range, BeamRng& rng,
                        double& range) noexcept {
  const auto diffuse = [&] {
    range = std::max(min_range, d + m.sigma_at(d) * rng.normal());
    return Response::Return;
  };
  switch (m.surface) {
    case Surface::Diffuse: return diffuse();
    case Surface::Absorbing:
      if (rng.bernoulli(m.p_return)) return diffuse();
      return Response::NoReturn;
    case Surface::Specular: range = rng.uniform(min_range, max_range); return Response::Return;
    case Surface::Transparent:
      if (rng.bernoulli(m.p_pass)) return Response::Pass;
      return diffuse();
  }
  return Response::NoReturn;
}

}  // namespace intervox::sim
