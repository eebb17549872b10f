#pragma once
// What the readers of JSON documents (a job file, a formula model file: job.hpp, formula/formula_model.hpp) report:
// one issue per problem, at a JSON Pointer, and the misspelling rule their "did you mean" suggestions use. The
// lowest layer of the readers: it includes nothing of the host.
#include <string>
#include <string_view>

namespace nonsep::host {

// One problem in a job file. `path` is a JSON Pointer ("/integrator/order"; "" for the whole document),
// `found` describes what is there ("\"5/3\"", "nothing", "a string"), `allowed` what would be accepted.
struct JobIssue {
  std::string path;
  std::string found;
  std::string allowed;
};
// "/integrator/order: found \"5/3\"; allowed: ..."
std::string to_string(const JobIssue& issue);

// Whether the key `written` is likely a misspelling of `meant`: equal but for letter case, or (both at least 3
// characters long) one edit away, two for names of 6 characters or more. The reader's messages name the likely
// intended key with it; no two keys of one object of a job file are that close (a test checks it), so a
// suggestion never names another valid key.
bool looks_like_misspelling(std::string_view written, std::string_view meant);

}  // namespace nonsep::host
