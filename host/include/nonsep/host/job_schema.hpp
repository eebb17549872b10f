#pragma once
// The JSON Schema (draft 2020-12) of job files, as `nonsep schema` prints it and schemas/job.schema.json holds it
// (a test fails when the two differ). Generated from the job reader's key tables (host/src/job/job_keys.hpp: keys,
// types, integer ranges, defaults, required keys) and the core's scheme catalogue (schemes, their options with
// defaults, their orders), so that the schema says what the reader accepts. The reader checks more than a schema
// can express (see the schema's own description).
#include <nlohmann/json.hpp>

namespace nonsep::host {

nlohmann::ordered_json job_schema();

}  // namespace nonsep::host
