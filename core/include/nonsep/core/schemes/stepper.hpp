#pragma once
// What a scheme is to the runtime-chosen integrators (integrator.hpp, tangent_integrator.hpp). As OrdinaryDiffEq.jl
// parts an algorithm from its cache, a scheme type is what the user chooses and a stepper what the scheme keeps:
//
//   struct TripletScheme {                       // IntegrationScheme: the algorithm
//     using Options = ChinOptions;               // its options, typed (scheme_options.hpp)
//     using Stepper = TripletComposition<...>;   // its stepper
//     static Options defaults();                 // optional: its options' defaults, when not Options{}'s
//     static SchemeDescription description();    // its catalogue entry: name, options (describe_options of its
//                                                // defaults), orders, flags
//     static IntegratorDescription describe(const Options&);  // what it is with these options (order, flags,
//                                                // cost), without building a stepper; InvalidArgument as make
//     static Stepper make(const Options&, HamiltonianForm);  // InvalidArgument for an option it refuses
//   };
//
// describe(options) and the stepper's own describe() say the same: both read the stepper's static description().
//
// A Stepper steps a batch (step(model, x, dt)) and counts its evaluations; what else it offers the integrators find
// by asking: step_n (n steps in one call, bit for bit n steps), prime (the first-same-as-last gradient), private
// state per state (save_state, restore_state, compact, step_part, report), a stepper whose step needs more of the
// model than Model (a comparator: ModelWithThirdDerivatives), and a tangent map: an overload
// tangent_map_of(const Stepper&, std::size_t vectors_per_state) beside the tangent stepper, found by argument-
// dependent lookup.
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "nonsep/core/base/model.hpp"
#include "nonsep/core/base/phase_space_batch.hpp"
#include "nonsep/core/base/scheme_state.hpp"
#include "nonsep/core/schemes/integrator_description.hpp"
#include "nonsep/core/schemes/scheme_options.hpp"

namespace nonsep {

// How a stepper describes itself: an IntegratorDescription, or a description (the comparators',
// comparator_description.hpp) whose integrator_description() gives one.
template <class S>
concept Stepper = std::copyable<S> && requires(const S& stepper) {
  stepper.evaluations();
  requires std::convertible_to<decltype(stepper.describe()), IntegratorDescription> || requires {
    { stepper.describe().integrator_description() } -> std::convertible_to<IntegratorDescription>;
  };
};

template <Stepper S>
IntegratorDescription description_of(const S& stepper) {
  if constexpr (std::convertible_to<decltype(stepper.describe()), IntegratorDescription>)
    return stepper.describe();
  else
    return stepper.describe().integrator_description();
}

template <class A>
concept IntegrationScheme = SchemeOptions<typename A::Options> && Stepper<typename A::Stepper> &&
    requires(const typename A::Options& options, HamiltonianForm form) {
  { A::description() } -> std::convertible_to<SchemeDescription>;
  { A::describe(options) } -> std::convertible_to<IntegratorDescription>;
  { A::make(options, form) } -> std::same_as<typename A::Stepper>;
};

// The defaults of scheme A's options: A::defaults() where it has one (schemes that share an options struct and differ
// in a default: the triplet composition's order 4/3 where the basic step has 2/3), otherwise A::Options{}. Its
// catalogue entry's defaults are these (describe_options), so a job file that leaves an option out gets them.
template <IntegrationScheme A>
typename A::Options scheme_defaults() {
  if constexpr (requires {
                  { A::defaults() } -> std::convertible_to<typename A::Options>;
                })
    return A::defaults();
  else
    return typename A::Options{};
}

// A stepper that keeps private state per state (Tao's copies): the integrators hand batch changes on to it and its
// state out and back.
template <class S>
concept StepperWithPrivateState = requires(S& stepper, const S& kept, const PhaseSpaceBatch& states,
                                           const std::vector<bool>& retire, const SchemeState& state) {
  { kept.save_state(states) } -> std::same_as<SchemeState>;
  stepper.restore_state(state);
  stepper.compact(retire);
  { kept.report() } -> std::same_as<std::vector<SchemeFigure>>;
};

// The private state of the stepper a variant holds, for the integrators that hold one (BasicIntegrator,
// BasicTangentIntegrator): what a StepperWithPrivateState does, nothing (an empty state, no figures) for the others.
template <class... S>
void compact_private_state(std::variant<S...>& stepper, const std::vector<bool>& retire) {
  std::visit(
      [&](auto& s) {
        if constexpr (StepperWithPrivateState<std::decay_t<decltype(s)>>) s.compact(retire);
      },
      stepper);
}
template <class... S>
SchemeState save_private_state(const std::variant<S...>& stepper, const PhaseSpaceBatch& states) {
  return std::visit(
      [&](const auto& s) {
        if constexpr (StepperWithPrivateState<std::decay_t<decltype(s)>>)
          return s.save_state(states);
        else
          return SchemeState{};
      },
      stepper);
}
template <class... S>
void restore_private_state(std::variant<S...>& stepper, const SchemeState& state) {
  std::visit(
      [&](auto& s) {
        if constexpr (StepperWithPrivateState<std::decay_t<decltype(s)>>) s.restore_state(state);
      },
      stepper);
}
template <class... S>
std::vector<SchemeFigure> private_report(const std::variant<S...>& stepper) {
  return std::visit(
      [](const auto& s) {
        if constexpr (StepperWithPrivateState<std::decay_t<decltype(s)>>)
          return s.report();
        else
          return std::vector<SchemeFigure>{};
      },
      stepper);
}

namespace detail {
// std::variant of the distinct types among Ts, leaving out void: one alternative per stepper type however many
// schemes build it (gauss and implicit_midpoint build GaussLegendre).
template <class Variant, class... Ts>
struct DistinctVariant {
  using type = Variant;
};
template <class... Done, class T, class... Rest>
struct DistinctVariant<std::variant<Done...>, T, Rest...> {
  static constexpr bool skip = std::is_void_v<T> || (std::is_same_v<T, Done> || ...);
  using type = typename std::conditional_t<skip, DistinctVariant<std::variant<Done...>, Rest...>,
                                           DistinctVariant<std::variant<Done..., T>, Rest...>>::type;
};
}  // namespace detail
template <class... Ts>
using DistinctVariant = typename detail::DistinctVariant<std::variant<>, Ts...>::type;
template <class... Ts>
using DistinctVariantWithNone = typename detail::DistinctVariant<std::variant<std::monostate>, Ts...>::type;

// Calls f(std::type_identity<Scheme>{}) for the index-th of Schemes.
template <class... Schemes, class F>
void with_scheme_at(std::size_t index, F&& f) {
  std::size_t i = 0;
  static_cast<void>(((i++ == index ? (f(std::type_identity<Schemes>{}), true) : false) || ...));
}

}  // namespace nonsep
