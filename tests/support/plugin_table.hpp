#pragma once
// The function table of a test plugin written by hand against plugin_abi.h (no SDK), written out once: the test
// plugins give their required entries and set the optional ones they have on the result, so that a new ABI version
// changes this file, not every plugin.
//
//   const nonsep_plugin_api table = [] {
//     nonsep_plugin_api t = nonsep::testing::plugin_table(metadata, create, destroy, dimension, grad_T, grad_V,
//                                                         last_error);
//     t.hessian_T = hessian_T;   // ... the optional entries this plugin has
//     return t;
//   }();
//   NONSEP_DEFINE_PLUGIN(table);
//
// Output: a table of the current version (NONSEP_PLUGIN_ABI_VERSION, its struct size) whose optional entries are
// all null. An older version's table: set abi_version and struct_size (NONSEP_PLUGIN_V3_STRUCT_SIZE, ...) after.
#include <cstdint>

#include "nonsep/plugin_abi.h"

namespace nonsep::testing {

constexpr nonsep_plugin_api plugin_table(const char* (*metadata_json)(void),
                                         nonsep_status (*create)(const char*, nonsep_instance**, char*, size_t),
                                         void (*destroy)(nonsep_instance*), size_t (*dimension)(const nonsep_instance*),
                                         nonsep_status (*grad_T)(nonsep_instance*, const double*, double*, size_t),
                                         nonsep_status (*grad_V)(nonsep_instance*, const double*, double*, size_t),
                                         const char* (*last_error)(const nonsep_instance*)) {
  nonsep_plugin_api table{};
  table.abi_version = NONSEP_PLUGIN_ABI_VERSION;
  table.struct_size = static_cast<std::uint32_t>(sizeof(nonsep_plugin_api));
  table.metadata_json = metadata_json;
  table.create = create;
  table.destroy = destroy;
  table.dimension = dimension;
  table.grad_T = grad_T;
  table.grad_V = grad_V;
  table.last_error = last_error;
  return table;
}

}  // namespace nonsep::testing
