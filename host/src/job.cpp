#include "nonsep/host/job.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <set>
#include <sstream>

#include "nonsep/core/error.hpp"
#include "nonsep/core/integrator_description.hpp"
#include "nonsep/host/number_format.hpp"

namespace nonsep::host {

using nlohmann::json;

std::string to_string(const JobIssue& issue) {
  return (issue.path.empty() ? std::string("(document)") : issue.path) + ": found " + issue.found +
         "; allowed: " + issue.allowed;
}

namespace {
std::string report(const std::filesystem::path& job_file, const std::vector<JobIssue>& issues) {
  std::string text = "invalid job file " + job_file.string() + " (" + std::to_string(issues.size()) +
                     (issues.size() == 1 ? " problem)" : " problems)");
  for (const auto& issue : issues) text += "\n  " + to_string(issue);
  return text;
}
}  // namespace

InvalidJob::InvalidJob(const std::filesystem::path& job_file, std::vector<JobIssue> issues)
    : std::runtime_error(report(job_file, issues)), issues_(std::move(issues)) {}

namespace {

std::string escape_pointer_token(const std::string& token) {
  std::string escaped;
  for (char c : token) {
    if (c == '~')
      escaped += "~0";
    else if (c == '/')
      escaped += "~1";
    else
      escaped += c;
  }
  return escaped;
}

std::string child(const std::string& path, const std::string& key) { return path + "/" + escape_pointer_token(key); }
std::string child(const std::string& path, std::size_t index) { return path + "/" + std::to_string(index); }

// What was found, for messages: the JSON text, shortened.
std::string describe(const json& value) {
  std::string text = value.dump();
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return text;
}

// ---------------------------------------------------------------------------------------------------------------
// Pass 1: a SAX handler that builds the document like nlohmann's own DOM parser, but reports duplicate keys.
class StrictDocumentBuilder : public nlohmann::json_sax<json> {
 public:
  explicit StrictDocumentBuilder(std::vector<JobIssue>& issues) : issues_(issues) {}
  json& result() { return root_; }

  bool null() override { return add(nullptr); }
  bool boolean(bool value) override { return add(value); }
  bool number_integer(number_integer_t value) override { return add(value); }
  bool number_unsigned(number_unsigned_t value) override { return add(value); }
  bool number_float(number_float_t value, const string_t&) override { return add(value); }
  bool string(string_t& value) override { return add(value); }
  bool binary(binary_t& value) override { return add(json::binary(value)); }
  bool start_object(std::size_t) override { return open(json::object()); }
  bool start_array(std::size_t) override { return open(json::array()); }
  bool end_object() override { return close(); }
  bool end_array() override { return close(); }
  bool key(string_t& key) override {
    Frame& frame = frames_.back();
    if (frame.value->contains(key))
      issues_.push_back({child(frame.path, key), "the key \"" + key + "\" a second time in the same object",
                         "each key at most once (JSON readers disagree on which duplicate wins)"});
    frame.key = key;
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& error) override {
    std::string message = error.what();
    if (const auto bracket = message.find("] "); message.rfind("[json.exception", 0) == 0 && bracket != std::string::npos)
      message = message.substr(bracket + 2);
    issues_.push_back({"", "text that is not JSON (" + message + ")", "a JSON object as described in README.md"});
    return false;
  }

 private:
  struct Frame {
    json* value;
    std::string path;
    std::string key;  // objects: the key whose value comes next
  };

  // Places `value` where the parser is, returning it and the JSON Pointer to it.
  std::pair<json*, std::string> place(json value) {
    if (frames_.empty()) {
      root_ = std::move(value);
      return {&root_, ""};
    }
    Frame& frame = frames_.back();
    if (frame.value->is_array()) {
      const std::size_t index = frame.value->size();
      frame.value->push_back(std::move(value));
      return {&frame.value->back(), child(frame.path, index)};
    }
    json& slot = (*frame.value)[frame.key];
    slot = std::move(value);
    return {&slot, child(frame.path, frame.key)};
  }
  bool add(json value) {
    place(std::move(value));
    return true;
  }
  bool open(json container) {
    auto [where, path] = place(std::move(container));
    frames_.push_back({where, std::move(path), {}});
    return true;
  }
  bool close() {
    frames_.pop_back();
    return true;
  }

  std::vector<JobIssue>& issues_;
  json root_;
  std::vector<Frame> frames_;
};

// ---------------------------------------------------------------------------------------------------------------
// Pass 2 helpers. Each check adds an issue and returns nothing when the value is unacceptable.
class Checker {
 public:
  explicit Checker(std::vector<JobIssue>& issues) : issues_(issues) {}

  void issue(std::string path, std::string found, std::string allowed) {
    issues_.push_back({std::move(path), std::move(found), std::move(allowed)});
  }
  std::size_t issue_count() const { return issues_.size(); }

  bool object(const json& value, const std::string& path, const std::string& what) {
    if (value.is_object()) return true;
    issue(path, describe(value), what);
    return false;
  }

  // Reports every key of `object` not in `allowed`.
  void known_keys(const json& object, const std::string& path, const std::vector<std::string>& allowed) {
    for (const auto& [key, value] : object.items()) {
      if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
      std::string list;
      for (const auto& name : allowed) list += (list.empty() ? "" : ", ") + name;
      issue(child(path, key), "the unknown key \"" + key + "\"", "only the keys " + list);
    }
  }

  // The member `key` of an object, or nullptr; a missing required member is an issue.
  const json* member(const json& object, const std::string& path, const std::string& key, bool required,
                     const std::string& what) {
    const auto it = object.find(key);
    if (it != object.end()) return &*it;
    if (required) issue(child(path, key), "nothing (the key is missing)", what);
    return nullptr;
  }

  std::optional<double> finite_number(const json& value, const std::string& path, const std::string& what) {
    if (value.is_number()) {
      const double x = value.get<double>();
      if (std::isfinite(x)) return x;
    }
    issue(path, describe(value), what);
    return std::nullopt;
  }

  std::optional<std::int64_t> integer(const json& value, const std::string& path, std::int64_t minimum,
                                      std::int64_t maximum, const std::string& what) {
    if (value.is_number_unsigned() && value.get<std::uint64_t>() <= static_cast<std::uint64_t>(maximum)) {
      const auto x = static_cast<std::int64_t>(value.get<std::uint64_t>());
      if (x >= minimum) return x;
    } else if (value.is_number_integer() && !value.is_number_unsigned()) {
      const auto x = value.get<std::int64_t>();
      if (x >= minimum && x <= maximum) return x;
    } else if (value.is_number_float()) {
      // JSON Schema counts 10.0 as an integer; so does nonsep, within the range. The bounds are checked on the
      // double first: converting one outside the range of std::int64_t is undefined.
      const double x = value.get<double>();
      if (std::floor(x) == x && x >= -0x1p63 && x < 0x1p63) {
        const auto integral = static_cast<std::int64_t>(x);
        if (integral >= minimum && integral <= maximum) return integral;
      }
    }
    issue(path, describe(value), what);
    return std::nullopt;
  }

  std::optional<std::string> string(const json& value, const std::string& path, const std::string& what) {
    if (value.is_string() && !value.get<std::string>().empty()) return value.get<std::string>();
    issue(path, describe(value), what);
    return std::nullopt;
  }

  // A non-empty array of finite numbers.
  std::optional<std::vector<double>> vector(const json& value, const std::string& path) {
    if (!value.is_array() || value.empty()) {
      issue(path, describe(value), "a non-empty array of finite numbers, one per degree of freedom");
      return std::nullopt;
    }
    std::vector<double> result;
    bool ok = true;
    for (std::size_t i = 0; i < value.size(); ++i) {
      const auto x = finite_number(value[i], child(path, i), "a finite number");
      if (x)
        result.push_back(*x);
      else
        ok = false;
    }
    if (!ok) return std::nullopt;
    return result;
  }

 private:
  std::vector<JobIssue>& issues_;
};

std::string scheme_names() {
  std::string list;
  for (const auto& scheme : scheme_catalogue()) list += (list.empty() ? "\"" : ", \"") + scheme.name + "\"";
  return list;
}

// The value of one catalogue parameter, as the job wrote it or as its default text.
struct OptionValue {
  double number = 0.0;
  Fraction order;
};

// The only place where a catalogue parameter name meets IntegratorSpec's fields. A catalogue parameter without a
// field here is a programming error, caught by the host tests (which read every scheme's defaults).
void set_option(IntegratorSpec& spec, const ParameterDescription& parameter, const OptionValue& value) {
  if (parameter.name == "order" && parameter.kind == ParameterDescription::Kind::Order)
    spec.order = value.order;
  else if (parameter.name == "t2" && parameter.kind == ParameterDescription::Kind::Number)
    spec.t2 = value.number;
  else
    throw std::logic_error("the host does not know the integrator parameter '" + parameter.name + "'");
}

OptionValue default_option(const ParameterDescription& parameter) {
  OptionValue value;
  if (parameter.kind == ParameterDescription::Kind::Order) {
    value.order = Fraction::parse(parameter.default_text);
  } else {
    const auto& text = parameter.default_text;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value.number);
    if (ec != std::errc() || end != text.data() + text.size())
      throw std::logic_error("catalogue default '" + text + "' of '" + parameter.name + "' is not a number");
  }
  return value;
}

std::optional<OptionValue> read_option(Checker& check, const ParameterDescription& parameter, const json& value,
                                       const std::string& path) {
  OptionValue result;
  if (parameter.kind == ParameterDescription::Kind::Number) {
    const auto x = check.finite_number(value, path, "a finite number: " + parameter.description);
    if (!x) return std::nullopt;
    result.number = *x;
    return result;
  }
  const std::string allowed = "an exact fraction as a string (\"4/3\") or an integer (2): " + parameter.description;
  try {
    if (value.is_string()) {
      result.order = Fraction::parse(value.get<std::string>());
      return result;
    }
    if (value.is_number_integer()) {
      if (value.is_number_unsigned() && value.get<std::uint64_t>() > std::numeric_limits<std::int64_t>::max())
        throw InvalidArgument("too large");
      result.order = Fraction(value.get<std::int64_t>());
      return result;
    }
    // JSON Schema counts 2.0 as an integer; so does nonsep.
    if (value.is_number_float() && std::floor(value.get<double>()) == value.get<double>() &&
        std::abs(value.get<double>()) < 1e15) {
      result.order = Fraction(static_cast<std::int64_t>(value.get<double>()));
      return result;
    }
  } catch (const InvalidArgument&) {
  }
  check.issue(path, describe(value), allowed);
  return std::nullopt;
}

HamiltonianForm read_form(Checker& check, const json& document) {
  if (const json* form = check.member(document, "", "hamiltonian", false, "")) {
    if (*form == "TTV") return HamiltonianForm::TTV;
    if (*form == "VVT") return HamiltonianForm::VVT;
    check.issue("/hamiltonian", describe(*form),
                "\"TTV\" (H = T_i V_ij T_j, the default) or \"VVT\" (H = V_i T_ij V_j)");
  }
  return HamiltonianForm::TTV;
}

// An integrator object {"scheme": ..., options...} at `path` (already known to be an object). `extra_keys` are
// further keys the caller reads itself (a study's "label", "steps", "dt").
IntegratorSpec read_integrator_object(Checker& check, const json& integrator, const std::string& path,
                                      HamiltonianForm form, const std::vector<std::string>& extra_keys = {}) {
  IntegratorSpec spec;
  spec.form = form;
  std::optional<SchemeDescription> scheme;
  if (const json* name = check.member(integrator, path, "scheme", true, "one of " + scheme_names())) {
    if (name->is_string()) scheme = find_scheme(name->get<std::string>());
    if (scheme)
      spec.scheme = scheme->name;
    else
      check.issue(child(path, "scheme"), describe(*name), "one of " + scheme_names());
  }
  // With an unknown scheme, check the options every scheme shares so that their problems are reported too.
  std::vector<ParameterDescription> parameters;
  if (scheme) {
    parameters = scheme->parameters;
  } else {
    for (const auto& entry : scheme_catalogue())
      for (const auto& parameter : entry.parameters)
        if (std::none_of(parameters.begin(), parameters.end(),
                         [&](const ParameterDescription& known) { return known.name == parameter.name; }))
          parameters.push_back(parameter);
  }
  std::vector<std::string> keys{"scheme"};
  for (const auto& parameter : parameters) keys.push_back(parameter.name);
  keys.insert(keys.end(), extra_keys.begin(), extra_keys.end());
  check.known_keys(integrator, path, keys);

  for (const auto& parameter : parameters) {
    const std::string option_path = child(path, parameter.name);
    const json* given = check.member(integrator, path, parameter.name, parameter.default_text.empty(),
                                     parameter.description);
    if (!given) {
      if (!parameter.default_text.empty()) set_option(spec, parameter, default_option(parameter));
      continue;
    }
    const auto value = read_option(check, parameter, *given, option_path);
    if (!value || !scheme) continue;
    // The core decides what is valid: build the scheme with this one option set and the others at their defaults.
    IntegratorSpec probe{scheme->name, {}, {}, spec.form};
    for (const auto& other : parameters)
      if (!other.default_text.empty()) set_option(probe, other, default_option(other));
    set_option(probe, parameter, *value);
    try {
      const Integrator probe_integrator(probe);
      set_option(spec, parameter, *value);
    } catch (const InvalidArgument& error) {
      check.issue(option_path, describe(*given), error.what());
    }
  }
  return spec;
}

IntegratorSpec read_integrator(Checker& check, const json& document, HamiltonianForm form) {
  const json* integrator =
      check.member(document, "", "integrator", true, "an object with \"scheme\" (" + scheme_names() + ") and options");
  if (!integrator || !check.object(*integrator, "/integrator", "an object with \"scheme\" and the scheme's options")) {
    IntegratorSpec spec;
    spec.form = form;
    return spec;
  }
  return read_integrator_object(check, *integrator, "/integrator", form);
}

TimeGrid read_time(Checker& check, const json& document) {
  TimeGrid grid;
  const json* time = check.member(document, "", "time", true, "an object with \"dt\" and either \"t_end\" or \"steps\"");
  if (!time || !check.object(*time, "/time", "an object with \"dt\" and either \"t_end\" or \"steps\"")) return grid;
  check.known_keys(*time, "/time", {"dt", "t_end", "steps"});
  // NaN marks a value that is missing or invalid (and already reported).
  double dt = std::nan("");
  if (const json* value = check.member(*time, "/time", "dt", true, "the time step, a finite non-zero number")) {
    if (const auto x = check.finite_number(*value, "/time/dt", "the time step, a finite non-zero number")) {
      if (*x == 0.0)
        check.issue("/time/dt", describe(*value), "a finite non-zero number (negative integrates backwards in time)");
      else
        dt = *x;
    }
  }
  const json* t_end_value = time->contains("t_end") ? &(*time)["t_end"] : nullptr;
  const json* steps_value = time->contains("steps") ? &(*time)["steps"] : nullptr;
  if (t_end_value && steps_value) {
    check.issue("/time/steps", describe(*steps_value) + " together with /time/t_end",
                "either \"t_end\" or \"steps\", not both");
    return grid;
  }
  if (!t_end_value && !steps_value) {
    check.issue("/time/t_end", "nothing (neither \"t_end\" nor \"steps\" is given)",
                "either \"t_end\" (the time to end at) or \"steps\" (the number of steps of dt)");
    return grid;
  }
  if (t_end_value) {
    const auto t_end = check.finite_number(*t_end_value, "/time/t_end", "the end time, a finite non-zero number");
    if (!t_end || std::isnan(dt)) return grid;
    if (!(*t_end / dt > 0.0)) {
      check.issue("/time/t_end", describe(*t_end_value) + " with dt = " + format_number(dt),
                  "a non-zero end time of the same sign as dt (the run starts at t = 0)");
      return grid;
    }
    const double rounded = std::max(1.0, std::ceil(*t_end / dt * (1.0 - 1e-9)));
    if (!(rounded <= static_cast<double>(max_steps))) {
      check.issue("/time/t_end", describe(*t_end_value) + " with dt = " + format_number(dt) + ", which needs " +
                                     format_number(rounded) + " steps",
                  "at most " + std::to_string(max_steps) + " steps");
      return grid;
    }
    grid.steps = static_cast<std::uint64_t>(rounded);
    grid.t_end = *t_end;
    grid.dt = *t_end / static_cast<double>(grid.steps);
    grid.from_t_end = true;
  } else {
    const auto steps = check.integer(*steps_value, "/time/steps", 1, static_cast<std::int64_t>(max_steps),
                                     "an integer from 1 to " + std::to_string(max_steps));
    if (!steps || std::isnan(dt)) return grid;
    grid.steps = static_cast<std::uint64_t>(*steps);
    grid.dt = dt;
    grid.t_end = static_cast<double>(grid.steps) * dt;
    if (!std::isfinite(grid.t_end)) {
      check.issue("/time/steps", describe(*steps_value) + " with dt = " + format_number(dt),
                  "a number of steps whose end time steps * dt is finite");
      return grid;
    }
  }
  grid.dt_requested = dt;
  return grid;
}

// One state {"q": [...], "p": [...]}; appends it to `states` when valid.
void read_state(Checker& check, const json& value, const std::string& path, InitialStates& states,
                const std::string& first_path) {
  if (!check.object(value, path, "a state {\"q\": [...], \"p\": [...]}")) return;
  check.known_keys(value, path, {"q", "p"});
  std::optional<std::vector<double>> q, p;
  if (const json* v = check.member(value, path, "q", true, "the positions, an array of finite numbers"))
    q = check.vector(*v, child(path, "q"));
  if (const json* v = check.member(value, path, "p", true, "the momenta, an array of finite numbers"))
    p = check.vector(*v, child(path, "p"));
  if (!q || !p) return;
  if (q->size() != p->size()) {
    check.issue(child(path, "p"), std::to_string(p->size()) + " components",
                std::to_string(q->size()) + ", as many as q has");
    return;
  }
  if (states.dimension == 0) {
    states.dimension = q->size();
  } else if (q->size() != states.dimension) {
    check.issue(child(path, "q"), std::to_string(q->size()) + " components",
                std::to_string(states.dimension) + ", as many as the first state (" + first_path + ") has");
    return;
  }
  states.q.insert(states.q.end(), q->begin(), q->end());
  states.p.insert(states.p.end(), p->begin(), p->end());
  ++states.count;
}

// A study's time: {"t_end": T} only (the step sizes come from the study).
TimeGrid read_study_time(Checker& check, const json& document) {
  TimeGrid grid;
  const std::string what = "an object {\"t_end\": T}: a study runs every integrator to T with its own step counts";
  const json* time = check.member(document, "", "time", true, what);
  if (!time || !check.object(*time, "/time", what)) return grid;
  check.known_keys(*time, "/time", {"t_end"});
  if (const json* value = check.member(*time, "/time", "t_end", true, "the end time, a finite non-zero number"))
    if (const auto t_end = check.finite_number(*value, "/time/t_end", "the end time, a finite non-zero number")) {
      if (*t_end == 0.0)
        check.issue("/time/t_end", describe(*value), "a finite non-zero number (negative integrates backwards)");
      else
        grid.t_end = *t_end;
    }
  return grid;
}

// A list of step counts (`key` "steps") or step sizes (`key` "dt") at `path`, as distinct increasing step counts
// over `t_end` (0 when the end time is invalid: the sizes are then only checked).
std::optional<std::vector<std::uint64_t>> read_step_list(Checker& check, const json& value, const std::string& path,
                                                         const std::string& key, double t_end) {
  const bool counts = key == "steps";
  const std::string what = counts ? "a non-empty array of step counts, integers from 1 to " + std::to_string(max_steps)
                                  : "a non-empty array of step sizes, finite non-zero numbers of the sign of t_end";
  if (!value.is_array() || value.empty()) {
    check.issue(path, describe(value), what);
    return std::nullopt;
  }
  std::vector<std::uint64_t> result;
  bool ok = true;
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::string item = child(path, i);
    if (counts) {
      const auto n = check.integer(value[i], item, 1, static_cast<std::int64_t>(max_steps),
                                   "a step count, an integer from 1 to " + std::to_string(max_steps));
      if (n)
        result.push_back(static_cast<std::uint64_t>(*n));
      else
        ok = false;
      continue;
    }
    const auto dt = check.finite_number(value[i], item, "a step size, a finite non-zero number");
    if (!dt) {
      ok = false;
      continue;
    }
    if (*dt == 0.0 || (t_end != 0.0 && !(t_end / *dt > 0.0))) {
      check.issue(item, describe(value[i]), "a non-zero step size of the same sign as /time/t_end");
      ok = false;
      continue;
    }
    if (t_end == 0.0) continue;
    const double rounded = std::max(1.0, std::ceil(t_end / *dt * (1.0 - 1e-9)));
    if (!(rounded <= static_cast<double>(max_steps))) {
      check.issue(item, describe(value[i]) + ", which needs " + format_number(rounded) + " steps to /time/t_end",
                  "at most " + std::to_string(max_steps) + " steps");
      ok = false;
      continue;
    }
    result.push_back(static_cast<std::uint64_t>(rounded));
  }
  if (!ok) return std::nullopt;
  std::sort(result.begin(), result.end());
  if (std::adjacent_find(result.begin(), result.end()) != result.end()) {
    check.issue(path, describe(value) + ", which gives the same step count twice",
                "distinct step " + std::string(counts ? "counts" : "sizes (each gives ceil(t_end / dt) steps)"));
    return std::nullopt;
  }
  return result;
}

// /study/steps or /study/dt (exactly one) inside `object` at `path`; `required` when the object must give one.
std::optional<std::vector<std::uint64_t>> read_steps_or_dt(Checker& check, const json& object, const std::string& path,
                                                           double t_end, bool required, std::string& from,
                                                           const std::string& from_prefix) {
  const bool has_steps = object.contains("steps"), has_dt = object.contains("dt");
  if (has_steps && has_dt) {
    check.issue(child(path, "dt"), describe(object["dt"]) + " together with " + child(path, "steps"),
                "either \"steps\" (step counts over t_end) or \"dt\" (step sizes), not both");
    return std::nullopt;
  }
  if (!has_steps && !has_dt) {
    if (required)
      check.issue(child(path, "steps"), "nothing (neither \"steps\" nor \"dt\" is given)",
                  "\"steps\": [step counts over /time/t_end] or \"dt\": [step sizes]");
    return std::nullopt;
  }
  const std::string key = has_steps ? "steps" : "dt";
  from = from_prefix + key;
  return read_step_list(check, object[key], child(path, key), key, t_end);
}

std::string default_label(const IntegratorSpec& spec) {
  return spec.scheme == "basic" ? spec.scheme : spec.scheme + " " + spec.order.to_string();
}

Study read_study(Checker& check, const json& study_value, HamiltonianForm form, double t_end) {
  Study study;
  const std::string path = "/study";
  const std::string what =
      "an object {\"integrators\": [...], \"steps\": [...] or \"dt\": [...], \"reference\": {\"q\", \"p\"}}";
  if (!check.object(study_value, path, what)) return study;
  check.known_keys(study_value, path, {"integrators", "steps", "dt", "reference"});
  std::string study_from;
  const std::size_t before = check.issue_count();
  const auto study_steps = read_steps_or_dt(check, study_value, path, t_end, false, study_from, "study.");
  const bool study_steps_invalid = check.issue_count() != before;

  const json* list = check.member(study_value, path, "integrators", true,
                                  "a non-empty array of integrators, each as /integrator of a run");
  if (list && (!list->is_array() || list->empty())) {
    check.issue(child(path, "integrators"), describe(*list),
                "a non-empty array of integrators, each {\"scheme\": ..., options, \"label\", \"steps\" or \"dt\"}");
    list = nullptr;
  }
  for (std::size_t i = 0; list && i < list->size(); ++i) {
    const std::string item = child(child(path, "integrators"), i);
    const json& entry = (*list)[i];
    if (!check.object(entry, item, "an integrator {\"scheme\": ..., options, \"label\", \"steps\" or \"dt\"}")) continue;
    StudyIntegrator integrator;
    integrator.spec = read_integrator_object(check, entry, item, form, {"label", "steps", "dt"});
    integrator.label = default_label(integrator.spec);
    if (const json* label = check.member(entry, item, "label", false, ""))
      if (auto text = check.string(*label, child(item, "label"), "a non-empty string naming the integrator"))
        integrator.label = *text;
    std::string from;
    if (entry.contains("steps") || entry.contains("dt")) {
      if (auto steps = read_steps_or_dt(check, entry, item, t_end, true, from, "integrator.")) {
        integrator.steps = std::move(*steps);
        integrator.steps_from = from;
      }
    } else if (study_steps) {
      integrator.steps = *study_steps;
      integrator.steps_from = study_from;
    } else if (!study_steps_invalid) {
      check.issue(child(item, "steps"), "nothing: neither this integrator nor /study gives steps or dt",
                  "\"steps\" or \"dt\" here, or in /study for every integrator");
    }
    for (const auto& other : study.integrators)
      if (other.label == integrator.label)
        check.issue(child(item, "label"), "\"" + integrator.label + "\", the label of an earlier integrator",
                    "a distinct label per integrator (add \"label\" to tell them apart)");
    study.integrators.push_back(std::move(integrator));
  }

  if (const json* reference = check.member(study_value, path, "reference", false, "")) {
    const std::string reference_path = child(path, "reference");
    if (check.object(*reference, reference_path, "the exact state at t_end {\"q\": [...], \"p\": [...]}")) {
      InitialStates state;
      read_state(check, *reference, reference_path, state, reference_path);
      study.reference_q = std::move(state.q);
      study.reference_p = std::move(state.p);
    }
  }
  return study;
}

Analysis read_analysis(Checker& check, const json& value) {
  Analysis analysis;
  const std::string what = "an object {\"closest_return_after\": t}";
  if (!check.object(value, "/analysis", what)) return analysis;
  check.known_keys(value, "/analysis", {"closest_return_after"});
  if (const json* after = check.member(value, "/analysis", "closest_return_after", false, ""))
    analysis.closest_return_after = check.finite_number(
        *after, "/analysis/closest_return_after",
        "a finite time: from then on the smallest phase-space distance to the initial state is tracked");
  return analysis;
}

// One axis of a grid: a number, {"from", "to", "count"} or {"values": [...]}.
std::optional<std::vector<double>> read_axis(Checker& check, const json& value, const std::string& path) {
  const std::string what =
      "a number (a fixed value), {\"from\": a, \"to\": b, \"count\": n} (n evenly spaced values from a to b) or "
      "{\"values\": [...]} (the values listed)";
  if (value.is_number()) {
    const auto x = check.finite_number(value, path, "a finite number");
    if (!x) return std::nullopt;
    return std::vector<double>{*x};
  }
  if (!value.is_object()) {
    check.issue(path, describe(value), what);
    return std::nullopt;
  }
  if (value.contains("values")) {
    check.known_keys(value, path, {"values"});
    const json& values = value["values"];
    return check.vector(values, child(path, "values"));
  }
  check.known_keys(value, path, {"from", "to", "count"});
  std::optional<double> from, to;
  std::optional<std::int64_t> count;
  if (const json* v = check.member(value, path, "from", true, "the first value, a finite number"))
    from = check.finite_number(*v, child(path, "from"), "the first value, a finite number");
  if (const json* v = check.member(value, path, "to", true, "the last value, a finite number"))
    to = check.finite_number(*v, child(path, "to"), "the last value, a finite number");
  if (const json* v = check.member(value, path, "count", true, "the number of values, an integer >= 1"))
    count = check.integer(*v, child(path, "count"), 1, static_cast<std::int64_t>(max_initial_states),
                          "the number of values, an integer from 1 to " + std::to_string(max_initial_states));
  if (!from || !to || !count) return std::nullopt;
  std::vector<double> values(static_cast<std::size_t>(*count));
  const auto n = values.size();
  for (std::size_t i = 0; i < n; ++i)
    values[i] = i + 1 == n && n > 1 ? *to : *from + (*to - *from) * static_cast<double>(i) / static_cast<double>(n - 1);
  return values;
}

void read_grid(Checker& check, const json& grid, InitialStates& states) {
  const std::string path = "/initial/grid";
  if (!check.object(grid, path, "an object {\"q\": [axis, ...], \"p\": [axis, ...]}, one axis per component")) return;
  check.known_keys(grid, path, {"q", "p"});
  std::vector<std::vector<double>> axes;
  std::size_t count = 1;  // states: the product of the axes' sizes
  std::size_t sizes[2] = {0, 0};
  bool ok = true;
  for (int which = 0; which < 2; ++which) {
    const std::string name = which == 0 ? "q" : "p";
    const json* list = check.member(grid, path, name, true, "an array of axes, one per component");
    if (!list) {
      ok = false;
      continue;
    }
    if (!list->is_array() || list->empty()) {
      check.issue(child(path, name), describe(*list), "a non-empty array of axes, one per component");
      ok = false;
      continue;
    }
    sizes[which] = list->size();
    for (std::size_t i = 0; i < list->size(); ++i) {
      auto axis = read_axis(check, (*list)[i], child(child(path, name), i));
      if (!axis) {
        ok = false;
        continue;
      }
      // Stops at the first axis that makes the grid too large, before reading (and allocating) the others.
      if (count > max_initial_states / axis->size()) {
        check.issue(path, "a grid of more than " + std::to_string(max_initial_states) + " states",
                    "at most " + std::to_string(max_initial_states) + " states");
        return;
      }
      count *= axis->size();
      axes.push_back(std::move(*axis));
    }
  }
  if (sizes[0] && sizes[1] && sizes[0] != sizes[1]) {
    check.issue(child(path, "p"), std::to_string(sizes[1]) + " axes",
                std::to_string(sizes[0]) + ", as many as q has");
    ok = false;
  }
  if (!ok) return;
  // Row-major over the axes in the order q0, q1, ..., p0, p1, ...: the last axis varies fastest.
  const std::size_t n = sizes[0];
  if (count > max_initial_values / n) {
    check.issue(path, "a grid of " + std::to_string(count) + " states of dimension " + std::to_string(n),
                "at most " + std::to_string(max_initial_values) + " numbers in q (states times dimension)");
    return;
  }
  states.dimension = n;
  states.count = count;
  states.q.resize(count * n);
  states.p.resize(count * n);
  // Axis a repeats each of its values `stride` times (the product of the later axes' sizes), the whole pattern
  // count / (size * stride) times; no division per value.
  std::size_t stride = count;
  for (std::size_t a = 0; a < axes.size(); ++a) {
    const std::vector<double>& axis = axes[a];
    stride /= axis.size();
    double* column = a < n ? states.q.data() + a : states.p.data() + (a - n);
    std::size_t b = 0;
    while (b < count)
      for (const double value : axis)
        for (std::size_t r = 0; r < stride; ++r, ++b) column[b * n] = value;
  }
}

InitialStates read_initial(Checker& check, const json& document) {
  InitialStates states;
  const std::string what =
      "one state {\"q\": [...], \"p\": [...]}, an array of such states, or {\"grid\": {\"q\": [axes], \"p\": [axes]}}";
  const json* initial = check.member(document, "", "initial", true, what);
  if (!initial) return states;
  if (initial->is_array()) {
    states.shape = "list";
    if (initial->empty()) check.issue("/initial", "an empty array", "at least one state");
    if (initial->size() > max_initial_states)
      check.issue("/initial", std::to_string(initial->size()) + " states",
                  "at most " + std::to_string(max_initial_states) + " states");
    for (std::size_t i = 0; i < initial->size(); ++i)
      read_state(check, (*initial)[i], child("/initial", i), states, "/initial/0");
  } else if (initial->is_object() && initial->contains("grid")) {
    states.shape = "grid";
    check.known_keys(*initial, "/initial", {"grid"});
    read_grid(check, (*initial)["grid"], states);
  } else if (initial->is_object()) {
    states.shape = "single";
    read_state(check, *initial, "/initial", states, "/initial");
  } else {
    check.issue("/initial", describe(*initial), what);
  }
  return states;
}

}  // namespace

std::optional<json> parse_job_text(const std::string& text, std::vector<JobIssue>& issues) {
  const std::size_t before = issues.size();
  StrictDocumentBuilder builder(issues);
  const bool parsed = json::sax_parse(text, &builder);
  if (!parsed || issues.size() != before) return std::nullopt;
  return std::move(builder.result());
}

Job parse_job(const json& document, const std::filesystem::path& job_file, std::vector<JobIssue>& issues) {
  Checker check(issues);
  Job job;
  job.file = job_file;
  job.directory = job_file.parent_path().empty() ? std::filesystem::path(".") : job_file.parent_path();
  if (!check.object(document, "",
                    "a JSON object with the keys model, integrator, initial, time (README.md, section Running nonsep)"))
    return job;
  check.known_keys(document, "",
                   {"$schema", "description", "model", "hamiltonian", "integrator", "initial", "time", "output",
                    "analysis", "study", "checkpoint"});
  if (const json* value = check.member(document, "", "$schema", false, ""))
    check.string(*value, "/$schema", "a string (the JSON Schema the file follows; ignored by nonsep)");
  if (const json* value = check.member(document, "", "description", false, ""))
    if (!value->is_string()) check.issue("/description", describe(*value), "a string (free text, ignored by nonsep)");

  const std::string model_what = "an object {\"plugin\": name or path, \"parameters\": {...}}";
  if (const json* model = check.member(document, "", "model", true, model_what);
      model && check.object(*model, "/model", model_what)) {
    check.known_keys(*model, "/model", {"plugin", "parameters"});
    if (const json* plugin = check.member(*model, "/model", "plugin", true,
                                          "a plugin name (see `nonsep models`) or a path to a .so file"))
      if (auto name = check.string(*plugin, "/model/plugin", "a plugin name (see `nonsep models`) or a path to a .so file"))
        job.plugin = *name;
    if (const json* parameters = check.member(*model, "/model", "parameters", false, ""))
      if (check.object(*parameters, "/model/parameters", "an object of the plugin's parameters (see `nonsep inspect`)"))
        job.parameters = *parameters;
  }

  const HamiltonianForm form = read_form(check, document);
  job.initial = read_initial(check, document);
  if (const json* study = check.member(document, "", "study", false, "")) {
    if (document.contains("integrator"))
      check.issue("/integrator", "an integrator together with /study",
                  "no /integrator in a study: each entry of /study/integrators is one");
    if (document.contains("analysis"))
      check.issue("/analysis", "an analysis together with /study", "/analysis in single runs only");
    if (document.contains("checkpoint"))
      check.issue("/checkpoint", "a checkpoint policy together with /study",
                  "/checkpoint in single runs only (a study is not resumed)");
    job.integrator.form = form;
    job.time = read_study_time(check, document);
    job.study = read_study(check, *study, form, job.time.t_end);
    if (job.initial.count > 1)
      check.issue("/initial", std::to_string(job.initial.count) + " states",
                  "one state: a study runs every integrator from the same initial state");
    if (!job.study->reference_q.empty() && job.initial.dimension != 0 &&
        job.study->reference_q.size() != job.initial.dimension)
      check.issue("/study/reference/q", std::to_string(job.study->reference_q.size()) + " components",
                  std::to_string(job.initial.dimension) + ", as many as the initial state has");
  } else {
    job.integrator = read_integrator(check, document, form);
    job.time = read_time(check, document);
    if (const json* analysis = check.member(document, "", "analysis", false, ""))
      job.analysis = read_analysis(check, *analysis);
  }

  std::filesystem::path output = job_file.stem().string() + ".out";
  if (const json* section = check.member(document, "", "output", false, "");
      section && check.object(*section, "/output", "an object {\"directory\": ..., \"every\": ...}")) {
    check.known_keys(*section, "/output", {"directory", "every", "energy_every"});
    if (const json* directory = check.member(*section, "/output", "directory", false, ""))
      if (auto text = check.string(*directory, "/output/directory",
                                   "a folder name or path, relative to the job file's folder"))
        output = *text;
    if (const json* every = check.member(*section, "/output", "every", false, ""))
      if (auto stride = check.integer(*every, "/output/every", 0, std::numeric_limits<std::int64_t>::max(),
                                      "an integer >= 0: write every n-th step to trajectory.csv (0: no trajectory)"))
        job.every = static_cast<std::uint64_t>(*stride);
    if (const json* energy_every = check.member(*section, "/output", "energy_every", false, ""))
      if (auto stride = check.integer(*energy_every, "/output/energy_every", 0,
                                      std::numeric_limits<std::int64_t>::max(),
                                      "an integer >= 0: also evaluate H every n-th step (0: only at the written "
                                      "samples, the start and the end)"))
        job.energy_every = static_cast<std::uint64_t>(*stride);
  }
  job.output_directory = output.is_absolute() ? output : job.directory / output;

  const std::string checkpoint_what = "an object {\"every_steps\": n, \"every_seconds\": s}";
  if (const json* section = check.member(document, "", "checkpoint", false, "");
      section && check.object(*section, "/checkpoint", checkpoint_what)) {
    check.known_keys(*section, "/checkpoint", {"every_steps", "every_seconds"});
    if (const json* value = check.member(*section, "/checkpoint", "every_steps", false, ""))
      if (auto steps = check.integer(*value, "/checkpoint/every_steps", 0, static_cast<std::int64_t>(max_steps),
                                     "an integer from 0 to " + std::to_string(max_steps) +
                                         ": save a checkpoint every n steps (0: not by steps)"))
        job.checkpoint.every_steps = static_cast<std::uint64_t>(*steps);
    if (const json* value = check.member(*section, "/checkpoint", "every_seconds", false, "")) {
      const std::string what = "a finite number >= 0: save a checkpoint every s seconds of wall time (0: not by time)";
      if (auto seconds = check.finite_number(*value, "/checkpoint/every_seconds", what)) {
        if (*seconds < 0.0)
          check.issue("/checkpoint/every_seconds", describe(*value), what);
        else
          job.checkpoint.every_seconds = *seconds;
      }
    }
  }
  return job;
}

void check_model_parameters(const json& given, const std::vector<PluginParameter>& declared,
                            std::vector<JobIssue>& issues) {
  Checker check(issues);
  std::string names;
  for (const auto& parameter : declared) names += (names.empty() ? "" : ", ") + parameter.name;
  for (const auto& [name, value] : given.items()) {
    const std::string path = child("/model/parameters", name);
    const auto it = std::find_if(declared.begin(), declared.end(),
                                 [&key = name](const PluginParameter& parameter) { return parameter.name == key; });
    if (it == declared.end()) {
      check.issue(path, "the unknown parameter \"" + name + "\"",
                  names.empty() ? "none: this plugin has no parameters" : "the plugin's parameters " + names);
      continue;
    }
    std::string range;
    if (it->minimum) range += " >= " + format_number(*it->minimum);
    if (it->minimum && it->maximum) range += " and";
    if (it->maximum) range += " <= " + format_number(*it->maximum);
    if (!it->unit.empty()) range += " (" + it->unit + ")";
    double x = 0.0;
    if (it->type == "boolean") {
      if (!value.is_boolean()) check.issue(path, describe(value), "true or false: " + it->description);
      continue;
    } else if (it->type == "integer") {
      if (!value.is_number_integer()) {
        check.issue(path, describe(value), "an integer" + range + ": " + it->description);
        continue;
      }
      x = value.get<double>();
    } else {
      if (!value.is_number() || !std::isfinite(value.get<double>())) {
        check.issue(path, describe(value), "a finite number" + range + ": " + it->description);
        continue;
      }
      x = value.get<double>();
    }
    if ((it->minimum && x < *it->minimum) || (it->maximum && x > *it->maximum))
      check.issue(path, describe(value), "a value" + range + ": " + it->description);
  }
}

void check_dimension(const InitialStates& initial, std::size_t model_dimension, std::vector<JobIssue>& issues) {
  if (initial.count == 0 || initial.dimension == model_dimension) return;
  const std::string path = initial.shape == "list" ? "/initial/0/q" : initial.shape == "grid" ? "/initial/grid/q" : "/initial/q";
  issues.push_back({path,
                    std::to_string(initial.dimension) + (initial.shape == "grid" ? " axes" : " components") +
                        (initial.shape == "list" && initial.count > 1 ? " (in every state)" : ""),
                    std::to_string(model_dimension) + ", the dimension of the model (for q and p alike)"});
}

LoadedJob load_job(const std::filesystem::path& job_file) {
  std::vector<JobIssue> issues;
  std::ifstream in(job_file, std::ios::binary);
  std::ostringstream text;
  if (in) text << in.rdbuf();
  if (!in || in.bad()) {
    issues.push_back({"", "no readable file at " + job_file.string(), "the path of a readable job file"});
    throw InvalidJob(job_file, std::move(issues));
  }
  const auto document = parse_job_text(text.str(), issues);
  if (!document) throw InvalidJob(job_file, std::move(issues));

  LoadedJob loaded{parse_job(*document, job_file, issues), {}, {}};
  const Job& job = loaded.job;
  const bool plugin_named = std::none_of(issues.begin(), issues.end(), [](const JobIssue& issue) {
    return issue.path == "/model" || issue.path == "/model/plugin" || issue.path.empty();
  });
  if (plugin_named && !job.plugin.empty()) {
    bool loaded_plugin = false;
    try {
      loaded.plugin = load_plugin(job.plugin, job.directory);
      loaded_plugin = true;
    } catch (const std::exception& error) {
      issues.push_back({"/model/plugin", "\"" + job.plugin + "\", which cannot be loaded: " + error.what(),
                        "a plugin name listed by `nonsep models`, or the path of a plugin file"});
    }
    if (loaded_plugin) {
      const std::size_t before = issues.size();
      check_model_parameters(job.parameters, loaded.plugin.parameters(), issues);
      if (issues.size() == before) {
        try {
          loaded.model = loaded.plugin.create(job.parameters);
          check_dimension(job.initial, loaded.model.dimension(), issues);
        } catch (const std::exception& error) {
          issues.push_back({"/model/parameters", describe(job.parameters) + ", refused by the plugin: " + error.what(),
                            "parameters the plugin accepts (see `nonsep inspect " + job.plugin + "`)"});
        }
      }
    }
  }
  if (!issues.empty()) throw InvalidJob(job_file, std::move(issues));
  return loaded;
}

}  // namespace nonsep::host
