#pragma once
// A runtime-chosen integrator over a list of schemes (stepper.hpp): BasicIntegrator<Schemes...> builds the scheme a
// BasicIntegratorSpec names from its options and steps with it; its catalogue is the schemes' descriptions in list
// order. integrator.hpp names the shipped list (Integrator, IntegratorSpec); a test adds a scheme by listing it.
//
// A stepper may keep private state per state (Tao's extended copy (x, y)): the integrator hands the caller's batch
// changes on to it (compact() when states leave, step_part() when a step is redone state by state) and its state
// out and back as an opaque SchemeState (save_state(), restore_state(); scheme_state.hpp), so that the caller needs
// to know nothing of it.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "nonsep/core/schemes/stepper.hpp"

namespace nonsep {

template <IntegrationScheme... Schemes>
struct BasicIntegratorSpec {
  std::string scheme = "basic";  // a catalogue entry's name
  // The scheme's options; none (std::monostate): its defaults (scheme_defaults, BasicIntegratorSpec::options_of).
  DistinctVariantWithNone<typename Schemes::Options...> options = std::monostate{};
  HamiltonianForm form = HamiltonianForm::TTV;

  // The index of the scheme named `name` in the list, or the list's length.
  static std::size_t index_of(const std::string& name) {
    static const std::array<std::string, sizeof...(Schemes)> names{Schemes::description().name...};
    std::size_t index = 0;
    while (index < names.size() && names[index] != name) ++index;
    return index;
  }
  // The options of scheme A in this spec: those it holds, or A's defaults when it holds none. std::logic_error when
  // it holds another scheme's options (a programming error).
  template <class A>
  typename A::Options options_of() const {
    if (std::holds_alternative<std::monostate>(options)) return scheme_defaults<A>();
    if (const auto* held = std::get_if<typename A::Options>(&options)) return *held;
    throw std::logic_error("the integrator spec of scheme '" + scheme + "' holds the options of another scheme");
  }
};

// Catalogue option `parameter` of the spec's scheme (a Fraction for the order, a number otherwise; an integer
// option as a double), for readers: summaries, fingerprints. std::logic_error for an unknown scheme or an option the
// scheme's options do not have.
template <class... Schemes>
OptionValue option_value(const BasicIntegratorSpec<Schemes...>& spec, const ParameterDescription& parameter) {
  const std::size_t index = spec.index_of(spec.scheme);
  if (index == sizeof...(Schemes)) throw std::logic_error("option of the unknown scheme '" + spec.scheme + "'");
  OptionValue value;
  with_scheme_at<Schemes...>(index, [&](auto scheme) {
    value = read_option(spec.template options_of<typename decltype(scheme)::type>(), parameter.name);
  });
  return value;
}

// Sets option `parameter` of the spec's scheme to `value` (std::logic_error as option_value, and for a value of the
// other kind; InvalidArgument for an integer option and a number that is not whole, naming it).
template <class... Schemes>
void set_option(BasicIntegratorSpec<Schemes...>& spec, const ParameterDescription& parameter,
                const OptionValue& value) {
  const std::size_t index = spec.index_of(spec.scheme);
  if (index == sizeof...(Schemes)) throw std::logic_error("option of the unknown scheme '" + spec.scheme + "'");
  with_scheme_at<Schemes...>(index, [&](auto scheme) {
    auto options = spec.template options_of<typename decltype(scheme)::type>();
    write_option(options, parameter.name, value);
    spec.options = options;
  });
}

// A catalogue option's default (ParameterDescription::default_text) as its value. Throws std::logic_error when the
// text is not one (a programming error in the catalogue; the host's tests read every default).
OptionValue default_option_value(const ParameterDescription& parameter);

template <IntegrationScheme... Schemes>
class BasicIntegrator {
 public:
  using Spec = BasicIntegratorSpec<Schemes...>;
  using Stepper = DistinctVariant<typename Schemes::Stepper...>;

  // The schemes' descriptions, in list order.
  static std::span<const SchemeDescription> catalogue() {
    static const std::array<SchemeDescription, sizeof...(Schemes)> descriptions{Schemes::description()...};
    return descriptions;
  }

  // Throws InvalidArgument naming the problem: unknown scheme (listing the known ones), an option the scheme
  // refuses (t2 zero or not finite, an order it does not have, listing the valid ones; omega, stages).
  explicit BasicIntegrator(const Spec& spec) : spec_(spec), index_(known_index(spec)), stepper_(build()) {}

  // What the spec's scheme is (its name, order, flags, family and cost in basic steps), read from the scheme's type
  // and options without building a stepper. Throws InvalidArgument as the constructor does.
  static IntegratorDescription describe(const Spec& spec) {
    std::optional<IntegratorDescription> d;
    with_scheme_at<Schemes...>(known_index(spec), [&](auto scheme) {
      using A = typename decltype(scheme)::type;
      d = A::describe(spec.template options_of<A>());
    });
    d->scheme = spec.scheme;  // one stepper type may serve two entries (gauss, implicit_midpoint): the entry's name
    return *d;
  }

  template <Model M>
  void step(const M& model, PhaseSpaceBatch& x, double dt) {
    std::visit(
        [&](auto& stepper) {
          if constexpr (requires { stepper.step(model, x, dt); })
            stepper.step(model, x, dt);
          else
            throw InvalidArgument(needs_third_derivatives());
        },
        stepper_);
  }

  // n steps of dt: bit for bit n calls of step(model, x, dt). A stepper with step_n (the basic step, the triplet
  // composition and the multi-product expansion, through SeparableComposition) does its per-step bookkeeping once, so
  // that a model with a kernel takes the n steps in one call; the others take their steps one by one.
  template <Model M>
  void step_n(const M& model, PhaseSpaceBatch& x, double dt, std::uint64_t n) {
    std::visit(
        [&](auto& stepper) {
          if constexpr (requires { stepper.step_n(model, x, dt, n); })
            stepper.step_n(model, x, dt, n);
          else
            for (std::uint64_t k = 0; k < n; ++k) step(model, x, dt);
        },
        stepper_);
  }

  // Redoes one step for part of a batch: `part` holds states first .. first + part.count() - 1 of a batch of
  // `total` states whose step `before` (this integrator as it was before the step) was to take. A stepper with
  // private state per state takes that of those states from `before` and writes it back into its own; the others
  // step part as step() does.
  template <Model M>
  void step_part(const M& model, PhaseSpaceBatch& part, const BasicIntegrator& before, std::size_t first,
                 std::size_t total, double dt) {
    std::visit(
        [&](auto& stepper) {
          using S = std::decay_t<decltype(stepper)>;
          if constexpr (!StepperWithPrivateState<S>)
            step(model, part, dt);
          else if constexpr (requires { stepper.step_part(model, part, stepper, first, total, dt); })
            stepper.step_part(model, part, std::get<S>(before.stepper_), first, total, dt);
          else
            throw InvalidArgument(needs_third_derivatives());
        },
        stepper_);
  }

  // The states with retire[b] true leave the batch: a stepper with private state per state drops theirs.
  void compact(const std::vector<bool>& retire) { compact_private_state(stepper_, retire); }

  // The stepper's private state of the batch `states` it steps (empty for a stepper without one), and back: a
  // caller that checkpoints stores it (for any subset of the states, SchemeState::select) and restores it into an
  // integrator of the same spec stepping those states, which then goes on as if never stopped.
  SchemeState save_state(const PhaseSpaceBatch& states) const { return save_private_state(stepper_, states); }
  void restore_state(const SchemeState& state) { restore_private_state(stepper_, state); }
  // What the scheme reports about the steps this integrator took (Tao: omega and the largest copy distance); empty
  // for most schemes.
  std::vector<SchemeFigure> report() const { return private_report(stepper_); }

  const EvaluationCounts& evaluations() const {
    return std::visit([](const auto& stepper) -> const EvaluationCounts& { return stepper.evaluations(); }, stepper_);
  }
  // The scheme's name, order, flags and family (a comparator's t2 is 0 and basic_steps_per_step 1).
  IntegratorDescription describe() const { return describe(spec_); }
  // Whether the scheme is of the catalogue's family "comparator" (Tao, Gauss-Legendre): it steps only a model with
  // Hessians and third derivatives.
  bool is_comparator() const { return catalogue()[index_].family == "comparator"; }
  HamiltonianForm form() const { return spec_.form; }
  const Spec& spec() const { return spec_; }
  // The stepper the scheme built (BasicTangentIntegrator maps it to its tangent map).
  const Stepper& stepper() const { return stepper_; }

 private:
  // The index of the spec's scheme in the list; InvalidArgument naming the known ones for a name not in it.
  static std::size_t known_index(const Spec& spec) {
    const std::size_t index = spec.index_of(spec.scheme);
    if (index == sizeof...(Schemes)) {
      std::string known;
      for (const auto& scheme : catalogue()) known += (known.empty() ? "" : ", ") + scheme.name;
      throw InvalidArgument("unknown integrator scheme '" + spec.scheme + "'; the schemes are " + known);
    }
    return index;
  }
  Stepper build() const {
    std::optional<Stepper> built;
    with_scheme_at<Schemes...>(index_, [&](auto scheme) {
      using A = typename decltype(scheme)::type;
      built.emplace(A::make(spec_.template options_of<A>(), spec_.form));
    });
    return std::move(*built);
  }
  std::string needs_third_derivatives() const {
    return "the comparator scheme '" + spec_.scheme +
           "' integrates H from its gradient and needs a model with Hessians (hessian_T, hessian_V) and third "
           "derivatives (d3T, d3V); use a Chin scheme (basic, triplet, mpe) with this model";
  }

  Spec spec_;
  std::size_t index_;
  Stepper stepper_;
};

}  // namespace nonsep
