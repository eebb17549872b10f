// /initial: one state, a list of states, a grid or a file (initial_file.cpp), into InitialStates (state-major:
// component i of state b at b * dimension + i). Every shape is held to max_initial_states and max_initial_values,
// checked on the sizes of the JSON arrays before their numbers are copied.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

#include "nonsep/host/number_format.hpp"
#include "sections.hpp"

namespace nonsep::host::job_reader {

namespace {

const std::string values_limit =
    "at most " + std::to_string(max_initial_values) + " numbers in q (states times dimension)";

// The number of elements of value[key] when it is an array, else 0.
std::size_t array_size(const json& value, const char* key) {
  if (!value.is_object()) return 0;
  const auto it = value.find(key);
  return it != value.end() && it->is_array() ? it->size() : 0;
}

}  // namespace

namespace {

// GCC's and Clang's 128-bit integers (exact sums of two 20-digit decimals times a count), named once: __extension__
// tells -Wpedantic that the extension is meant.
__extension__ using Signed128 = __int128;
__extension__ using Unsigned128 = unsigned __int128;

// A double as its shortest round-trip decimal (std::to_chars): sign * digits * 10^exponent.
struct Decimal {
  bool negative = false;
  std::uint64_t digits = 0;  // at most 17 decimal digits
  int exponent = 0;
  int length = 0;  // decimal digits in `digits`
};

Decimal decimal(double x) {
  char text[40];
  const auto end = std::to_chars(text, text + sizeof text, x, std::chars_format::scientific).ptr;
  Decimal d;
  const char* c = text;
  if (*c == '-') {
    d.negative = true;
    ++c;
  }
  for (; c < end && *c != 'e'; ++c)
    if (*c != '.') {
      d.digits = d.digits * 10 + static_cast<std::uint64_t>(*c - '0');
      ++d.length;
    }
  int exponent = 0;
  std::from_chars(c + (c[1] == '+' ? 2 : 1), end, exponent);
  d.exponent = exponent - (d.length - 1);
  return d;
}

}  // namespace

double range_value(double from, double to, std::size_t count, std::size_t k) {
  if (k == 0) return from;
  if (k + 1 == count) return to;
  // Exactly, from the shortest decimals of the ends: N = a (count - 1 - k) + b k in units of 10^e, then N / (count - 1)
  // written with 30 decimals after the point and a last digit 1 for a remainder, which std::from_chars rounds to the
  // nearest double (the digits kept are more than any midpoint between doubles needs to be told from it here).
  Decimal a = decimal(from), b = decimal(to);
  if (a.digits == 0) a.exponent = b.exponent;
  if (b.digits == 0) b.exponent = a.exponent;
  const int e = std::min(a.exponent, b.exponent);
  const std::uint64_t d = count - 1;
  if (a.length + (a.exponent - e) <= 20 && b.length + (b.exponent - e) <= 20 && d <= 1'000'000'000) {
    const auto scaled = [e](const Decimal& x) {
      Signed128 value = static_cast<Signed128>(x.digits);
      for (int i = e; i < x.exponent; ++i) value *= 10;
      return x.negative ? -value : value;
    };
    const Signed128 n = scaled(a) * static_cast<Signed128>(d - k) + scaled(b) * static_cast<Signed128>(k);
    Unsigned128 magnitude = static_cast<Unsigned128>(n < 0 ? -n : n);
    Unsigned128 quotient = magnitude / d, remainder = magnitude % d;
    char integer[48], *i = integer + sizeof integer;
    do {
      *--i = static_cast<char>('0' + static_cast<int>(quotient % 10));
      quotient /= 10;
    } while (quotient != 0);
    std::string text = n < 0 ? "-" : "";
    text.append(i, integer + sizeof integer);
    text += '.';
    for (int digit = 0; digit < 30; ++digit) {
      remainder *= 10;
      text += static_cast<char>('0' + static_cast<int>(remainder / d));
      remainder %= d;
    }
    if (remainder != 0) text += '1';
    text += 'e' + std::to_string(e);
    double value = 0.0;
    if (std::from_chars(text.data(), text.data() + text.size(), value).ec == std::errc()) return value;
  }
  // Ends of very different scales (1e-30 and 1e10): in double arithmetic, the value kept between the ends and finite
  // when from * (count - 1 - k) would overflow.
  const double wa = static_cast<double>(d - k), wb = static_cast<double>(k), wd = static_cast<double>(d);
  const double value = (from * wa + to * wb) / wd;
  return std::clamp(std::isfinite(value) ? value : from * (wa / wd) + to * (wb / wd), std::min(from, to),
                    std::max(from, to));
}

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
    const KeyReader keys(check, value, path, values_axis_keys(), what);  // at most max_initial_states values
    return keys.numbers("values");
  }
  const KeyReader keys(check, value, path, range_axis_keys(), what);
  const auto from = keys.number("from"), to = keys.number("to");
  const auto count = keys.integer("count");
  if (!from || !to || !count) return std::nullopt;
  std::vector<double> values(static_cast<std::size_t>(*count));
  for (std::size_t k = 0; k < values.size(); ++k) values[k] = range_value(*from, *to, values.size(), k);
  return values;
}

namespace {

// Fills `states` with every combination of `axes` (q0, q1, ..., p0, p1, ...), row-major: the last axis varies
// fastest. `count` is the product of the axes' sizes, count * n within max_initial_values.
void fill_grid(const std::vector<std::vector<double>>& axes, std::size_t n, std::size_t count, InitialStates& states) {
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

void read_grid(Checker& check, const json& grid, InitialStates& states) {
  const std::string path = "/initial/grid";
  const KeyReader keys(check, grid, path, grid_keys(),
                       "an object {\"q\": [axis, ...], \"p\": [axis, ...]}, one axis per component");
  if (!keys.is_object()) return;
  std::vector<std::vector<double>> axes;
  std::size_t count = 1;  // states: the product of the axes' sizes
  std::size_t sizes[2] = {0, 0};
  bool ok = true;
  for (int which = 0; which < 2; ++which) {
    const std::string name = which == 0 ? "q" : "p";
    const json* list = keys.value(name);
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
    check.issue(path, "q of " + counted(sizes[0], "axis", "axes") + " and p of " + std::to_string(sizes[1]),
                "q and p of as many axes, the dimension of the model");
    ok = false;
  }
  if (!ok) return;
  const std::size_t n = sizes[0];
  if (count > max_initial_values / n) {
    check.issue(path, "a grid of " + std::to_string(count) + " states of dimension " + std::to_string(n), values_limit);
    return;
  }
  fill_grid(axes, n, count, states);
}

}  // namespace

void read_state(Checker& check, const json& value, const std::string& path, InitialStates& states,
                const std::string& first_path, const std::string& what) {
  // The table refuses an array over max_initial_values from its size, before any number is read.
  const KeyReader keys(check, value, path, state_keys(), what);
  const auto q = keys.numbers("q"), p = keys.numbers("p");
  if (!q || !p) return;
  // The length every state has: the first state's; in the first, q's and p's where they agree. When they do not, the
  // reader cannot tell which is wrong (the model's dimension comes later): the state is named, with both lengths.
  if (q->size() != p->size() && states.dimension == 0) {
    check.issue(path, "q of " + counted(q->size(), "component") + " and p of " + std::to_string(p->size()),
                "q and p of as many components, the dimension of the model");
    return;
  }
  if (states.dimension == 0) states.dimension = q->size();
  bool ok = true;
  for (const auto& [key, numbers] : {std::pair{"q", &*q}, std::pair{"p", &*p}})
    if (numbers->size() != states.dimension) {
      check.issue(child(path, key), counted(numbers->size(), "component"),
                  std::to_string(states.dimension) + ", as many as the first state (" + first_path + ") has");
      ok = false;
    }
  if (!ok) return;
  states.q.insert(states.q.end(), q->begin(), q->end());
  states.p.insert(states.p.end(), p->begin(), p->end());
  ++states.count;
}

InitialStates read_initial(Checker& check, const KeyReader& document, const std::filesystem::path& directory) {
  InitialStates states;
  const json* initial = document.value("initial");
  if (!initial) return states;
  if (initial->is_array()) {
    states.shape = "list";
    if (initial->empty()) check.issue("/initial", "an empty array", "at least one state");
    if (initial->size() > max_initial_states) {
      check.issue("/initial", std::to_string(initial->size()) + " states",
                  "at most " + std::to_string(max_initial_states) + " states");
      return states;
    }
    std::size_t values = 0;  // numbers in q of the states so far, counting those refused
    for (std::size_t i = 0; i < initial->size(); ++i) {
      const std::size_t dimension = array_size((*initial)[i], "q");
      values += dimension;
      if (values > max_initial_values) {
        const std::size_t shown = states.dimension != 0 ? states.dimension : dimension;
        check.issue("/initial", std::to_string(initial->size()) + " states of dimension " + std::to_string(shown),
                    values_limit);
        break;
      }
      read_state(check, (*initial)[i], child("/initial", i), states, "/initial/0");
    }
  } else if (initial->is_object() && initial->contains("grid")) {
    states.shape = "grid";
    const KeyReader keys(check, *initial, "/initial", initial_grid_keys(), allowed_text(document_keys()["initial"]));
    read_grid(check, (*initial)["grid"], states);
    read_energy_shell(check, keys, states);
  } else if (initial->is_object() && initial->contains("file")) {
    states.shape = "file";
    read_initial_file(check, *initial, directory, states);
  } else if (initial->is_object()) {
    states.shape = "single";
    read_state(check, *initial, "/initial", states, "/initial");
  } else {
    check.issue("/initial", describe(*initial), allowed_text(document_keys()["initial"]));
  }
  return states;
}

}  // namespace nonsep::host::job_reader

namespace nonsep::host {

void check_dimension(const InitialStates& initial, std::size_t model_dimension, std::vector<JobIssue>& issues,
                     bool formula) {
  if (initial.count == 0 || initial.dimension == model_dimension) return;
  const std::string path = initial.shape == "list"   ? "/initial/0/q"
                           : initial.shape == "grid" ? "/initial/grid/q"
                           : initial.shape == "file" ? "/initial/file"
                                                     : "/initial/q";
  issues.push_back(
      {path,
       (initial.shape == "grid" ? counted(initial.dimension, "axis", "axes")
                                : counted(initial.dimension, "component")) +
           (initial.shape == "list" && initial.count > 1 ? " (in every state)" : ""),
       std::to_string(model_dimension) + ", the dimension of the model (for q and p alike" +
           (formula ? "; the largest index its formulas use plus one, or its \"dimension\"" : "") +
           "): components count from 0, " +
           (model_dimension == 1 ? std::string("q0 only") : "q0 .. q" + std::to_string(model_dimension - 1))});
}

}  // namespace nonsep::host
