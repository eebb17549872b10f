// An SDK plugin whose constructor refuses a combination of parameters that each pass their range check, as a
// real model may: create() must fail with a message naming the parameter.
#include <nonsep/plugin_sdk.hpp>

// A plugin's own units read no JSON: the SDK's library does (nonsep/sdk/parameters.hpp says why). This plugin does
// not compile if the SDK's headers bring in nlohmann/json.hpp again.
#ifdef NLOHMANN_JSON_VERSION_MAJOR
#error "nonsep/plugin_sdk.hpp includes nlohmann/json.hpp: every plugin would compile the JSON library itself"
#endif

struct CreateFailing {
  static constexpr std::size_t dimension = 1;
  static constexpr nonsep::sdk::Parameter parameters[] = {
      {.name = "inner_radius", .type = nonsep::sdk::ParameterType::number, .default_value = 1.0, .minimum = 0.0},
      {.name = "outer_radius", .type = nonsep::sdk::ParameterType::number, .default_value = 2.0, .minimum = 0.0}};

  explicit CreateFailing(const nonsep::sdk::ParameterValues& values) {
    if (values.number("inner_radius") >= values.number("outer_radius"))
      throw nonsep::sdk::InvalidParameter("inner_radius",
                                          "parameter 'inner_radius' must be smaller than "
                                          "'outer_radius'");
  }
  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    return p[0] * p[0] / 2.0;
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    return q[0] * q[0] / 2.0;
  }
};

NONSEP_EXPORT_MODEL(CreateFailing, "create_failing", "0.1", "test plugin: create refuses inner >= outer",
                    "T = p^2/2, V = q^2/2");
