#pragma once
// One value of a plugin's (or formula model's) declared parameter, checked by the rule of
// nonsep::sdk::parameter_fault that the loader and the SDK apply too: the job reader's sweeps and /model/parameters,
// and a formula model's defaults against their ranges, all report it with this message.
#include <nlohmann/json.hpp>
#include <string>

#include "nonsep/host/json/checker.hpp"
#include "nonsep/host/plugin_loader.hpp"

namespace nonsep::host::job_reader {

// One value of `parameter` at `path`; `found` describes it. An issue naming the allowed type and range otherwise.
void check_parameter_value(Checker& check, const PluginParameter& parameter, const nlohmann::json& value,
                           const std::string& path, const std::string& found);

}  // namespace nonsep::host::job_reader
