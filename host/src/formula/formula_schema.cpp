// The schema of a formula model (formula_model.hpp: formula_schema), the job schema's $defs/formula.
#include <string>

#include "nonsep/host/formula/formula_model.hpp"

namespace nonsep::host::formula {

namespace {

// Exactly one of T and dT (or of V and dV), or H alone, as the job-file reference can put it in words.
nlohmann::ordered_json gradient_or_function(const std::string& function) {
  const std::string gradient = "d" + function;
  return {{"if", {{"required", {gradient}}}},
          {"then",
           {{"description", function + " given by its gradient " + gradient + ": " + function + " itself is absent."},
            {"not", {{"required", {function}}}}}},
          {"else",
           {{"description", "Without " + gradient + ", " + function + " is required, or H alone (a model given by H)."},
            {"oneOf", {{{"required", {function}}}, {{"required", {"H"}}}}}}}};
}

}  // namespace

nlohmann::ordered_json formula_schema() {
  nlohmann::ordered_json parameter_names = {{"pattern", "^[A-Za-z_][A-Za-z0-9_]{0,63}$"}};
  nlohmann::ordered_json object = {
      {"type", "object"},
      {"description",
       "A model written as formulas, H(q, p) or T and V of the product form, compiled on first use into a cached "
       "plugin (docs/formula-models.md)."},
      {"additionalProperties", false},
      {"allOf",
       {{{"if", {{"required", {"H"}}}},
         {"then",
          {{"description", "A model given by H: none of T, V, dT, dV, K and U."},
           {"not",
            {{"anyOf",
              {{{"required", {"T"}}},
               {{"required", {"V"}}},
               {{"required", {"dT"}}},
               {{"required", {"dV"}}},
               {{"required", {"K"}}},
               {{"required", {"U"}}}}}}}}}},
        gradient_or_function("T"),
        gradient_or_function("V")}},
      {"properties",
       {{"name",
         {{"type", "string"},
          {"pattern", "^[a-z_][a-z0-9_]{0,63}$"},
          {"default", "formula"},
          {"description", "The plugin's name (summary.json, `nonsep model compile`'s NAME.so)."}}},
        {"H",
         {{"type", "string"},
          {"minLength", 1},
          {"maxLength", max_formula_length},
          {"description",
           "H(q, p), a Hamiltonian of any shape, instead of T and V: as T, with q0, q1, ... and p0, p1, .... "
           "Served by gauss, implicit_midpoint and tao; Chin's schemes need the product form."}}},
        {"T",
         {{"type", "string"},
          {"minLength", 1},
          {"maxLength", max_formula_length},
          {"description",
           "T(p): numbers, p0, p1, ..., the parameters, pi, + - * / ^ (or **), parentheses and the "
           "functions abs acos acosh asin asinh atan atan2 atanh cbrt cos cosh cube erf exp expm1 "
           "hypot log log1p max min pow sin sinh sqrt square tan tanh."}}},
        {"V",
         {{"type", "string"},
          {"minLength", 1},
          {"maxLength", max_formula_length},
          {"description", "V(q): as T, with q0, q1, ... instead of p0, p1, ...."}}},
        {"dT",
         {{"type", "array"},
          {"minItems", 1},
          {"maxItems", max_formula_dimension},
          {"items", {{"type", "string"}, {"minLength", 1}, {"maxLength", max_formula_length}}},
          {"description",
           "Instead of T: its gradient, one formula of p0, p1, ... per component (dT/dp0, dT/dp1, ...). H_TTV and "
           "H_VVT need only the gradient and Hessian of T; its value is then not available (value_T throws). "
           "The run refuses a dT whose Jacobian is not symmetric at the initial states (not a gradient)."}}},
        {"dV",
         {{"type", "array"},
          {"minItems", 1},
          {"maxItems", max_formula_dimension},
          {"items", {{"type", "string"}, {"minLength", 1}, {"maxLength", max_formula_length}}},
          {"description", "Instead of V: its gradient, as dT with q0, q1, ...."}}},
        {"K",
         {{"type", "string"},
          {"minLength", 1},
          {"maxLength", max_formula_length},
          {"description", "Optional separable part K(p), a formula like T: H = T_i V_ij T_j + K + U."}}},
        {"U",
         {{"type", "string"},
          {"minLength", 1},
          {"maxLength", max_formula_length},
          {"description", "Optional separable part U(q), a formula like V."}}},
        {"parameters",
         {{"type", "object"},
          {"propertyNames", parameter_names},
          {"additionalProperties",
           {{"oneOf",
             {{{"type", "number"}},
              {{"type", "object"},
               {"additionalProperties", false},
               {"required", {"value"}},
               {"properties",
                {{"value", {{"type", "number"}, {"description", "The default value."}}},
                 {"min", {{"type", "number"}, {"description", "The smallest value allowed (inclusive)."}}},
                 {"max", {{"type", "number"}, {"description", "The largest value allowed (inclusive)."}}}}}}}}}},
          {"default", nlohmann::ordered_json::object()},
          {"description",
           "The formulas' parameters and their default values, each a number or {\"value\": default, \"min\": ..., "
           "\"max\": ...} with the range allowed (either bound optional); /model/parameters overrides the defaults, "
           "and a value or sweep outside a range is refused as for a plugin's parameter."}}},
        {"dimension",
         {{"type", "integer"},
          {"minimum", 1},
          {"maximum", max_formula_dimension},
          {"description", "The dimension n; default the largest variable index used plus one."}}}}}};
  return {{"oneOf",
           {object,
            {{"type", "string"},
             {"minLength", 1},
             {"description",
              "The path of a model file holding such an object, relative to the job file's "
              "folder."}}}}};
}

}  // namespace nonsep::host::formula
