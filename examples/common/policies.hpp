#pragma once
// The update and utility policies the command-line programs offer, by the names they take on the
// command line, and the one function that turns a pair of names into the compile-time grid type.
// Each program says which pairs it offers (an "offer": a struct with a static constexpr
// `offers<Update, Utility>()`); only offered pairs are instantiated, so a program compiles no
// grid type it cannot run.
#include <intervox/core/error.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include <intervox/update/dempster_shafer.hpp>
#include <intervox/update/imprecise_dirichlet.hpp>
#include <intervox/update/interval_update.hpp>

#include <algorithm>
#include <optional>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

namespace examples {

/// A policy type with the name it has on the command line.
template <class T>
struct NamedPolicy {
  using type = T;
  const char* name;
};

/// Every update policy a program may offer, in the order of the help texts.
inline constexpr std::tuple kUpdatePolicies{
    NamedPolicy<intervox::BayesLogOdds>{"bayes"},
    NamedPolicy<intervox::IntervalUpdate<intervox::LowerState>>{"interval-lower"},
    NamedPolicy<intervox::IntervalUpdate<intervox::MeanState>>{"interval-mean"},
    NamedPolicy<intervox::IntervalUpdate<intervox::UpperState>>{"interval-upper"},
    NamedPolicy<intervox::CompactIntervalUpdate<intervox::MeanState>>{"compact-interval-mean"},
    NamedPolicy<intervox::ImpreciseDirichletUpdate<intervox::MeanState>>{"dirichlet-mean"},
    NamedPolicy<intervox::DempsterShaferUpdate<intervox::MeanState>>{"belief-mean"},
};

/// Every utility policy a program may offer.
inline constexpr std::tuple kUtilityPolicies{
    NamedPolicy<intervox::Entropy>{"entropy"},
    NamedPolicy<intervox::MaxEntropy>{"max-entropy"},
    NamedPolicy<intervox::TotalUncertainty>{"total-uncertainty"},
};

/// True for the credal cells (Dirichlet counts, belief masses).
template <class U>
inline constexpr bool kCredalUpdate = false;
template <class S>
inline constexpr bool kCredalUpdate<intervox::ImpreciseDirichletUpdate<S>> = true;
template <class S>
inline constexpr bool kCredalUpdate<intervox::DempsterShaferUpdate<S>> = true;

namespace detail {
template <class Offer, class NU, class NH, class F>
void visit_if_offered(NU u, NH h, F& f) {
  if constexpr (Offer::template offers<typename NU::type, typename NH::type>()) f(u, h);
}
template <class Offer, class NU, class F>
void visit_utilities(NU u, F& f) {
  std::apply([&](auto... h) { (visit_if_offered<Offer>(u, h, f), ...); }, kUtilityPolicies);
}
}  // namespace detail

/// Calls `f(update, utility)` with the NamedPolicy of every pair the offer admits, in the order of
/// kUpdatePolicies x kUtilityPolicies.
template <class Offer, class F>
void for_each_offered(F&& f) {
  std::apply([&](auto... u) { (detail::visit_utilities<Offer>(u, f), ...); }, kUpdatePolicies);
}

/// The update names an offer admits with at least one utility (for `CLI::IsMember`).
template <class Offer>
std::vector<std::string> offered_updates() {
  std::vector<std::string> names;
  for_each_offered<Offer>([&](auto u, auto) {
    if (names.empty() || names.back() != u.name) names.emplace_back(u.name);
  });
  return names;
}

/// The utility names an offer admits with at least one update (for `CLI::IsMember`).
template <class Offer>
std::vector<std::string> offered_utilities() {
  std::vector<std::string> names;
  for_each_offered<Offer>([&](auto, auto h) {
    if (std::find(names.begin(), names.end(), h.name) == names.end()) names.emplace_back(h.name);
  });
  return names;
}

/// The utilities an offer admits with the update named \p update, joined by ", ".
template <class Offer>
std::string utilities_offered_with(const std::string& update) {
  std::string list;
  for_each_offered<Offer>([&](auto u, auto h) {
    if (u.name != update) return;
    if (!list.empty()) list += ", ";
    list += h.name;
  });
  return list;
}

/// Why the offer does not admit the pair named, or an empty string if it does. The programs throw
/// it as a CLI::ValidationError of --utility from `app.callback` (exit code 2 through cli_main).
template <class Offer>
std::string offer_error(const std::string& update, const std::string& utility) {
  const std::string with = utilities_offered_with<Offer>(update);
  if (with.empty()) return "'" + update + "' is not offered";
  bool found = false;
  for_each_offered<Offer>([&](auto u, auto h) { found = found || (u.name == update && h.name == utility); });
  if (found) return {};
  return "'" + utility + "' is not offered with --update " + update + " (offered: " + with + ")";
}

/// Calls `f.template operator()<Update, Utility>()` for the pair named and returns its result.
/// \tparam Offer a struct with `template <class U, class H> static constexpr bool offers()`
/// \tparam R the result type of f
/// \throws intervox::InvalidArgument (with offer_error's text) if the offer does not admit the pair.
template <class Offer, class R, class F>
R with_policies(const std::string& update, const std::string& utility, F&& f) {
  if (const std::string error = offer_error<Offer>(update, utility); !error.empty())
    throw intervox::InvalidArgument(error);
  std::optional<R> result;
  for_each_offered<Offer>([&](auto u, auto h) {
    using U = typename decltype(u)::type;
    using H = typename decltype(h)::type;
    if (!result && u.name == update && h.name == utility) result.emplace(f.template operator()<U, H>());
  });
  return std::move(*result);
}

}  // namespace examples
