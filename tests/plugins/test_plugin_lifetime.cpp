// The plugin's library stays loaded exactly as long as a Plugin or PluginModel from it is alive. Checked with
// dlopen(RTLD_NOLOAD), which finds a library only if it is currently loaded.
#include <dlfcn.h>
#include <doctest/doctest.h>

#include <filesystem>
#include <optional>

#include "nonsep/host/plugin_loader.hpp"

namespace test_plugin_lifetime {

namespace {

const std::filesystem::path plugin_file = std::filesystem::path(NONSEP_TEST_PLUGIN_DIR) / "evaluation_fails.so";

bool is_loaded() {
  void* handle = dlopen(plugin_file.c_str(), RTLD_NOW | RTLD_NOLOAD);
  if (handle != nullptr) dlclose(handle);
  return handle != nullptr;
}

}  // namespace

TEST_CASE("a model keeps its library loaded after the Plugin is gone, the last owner unloads it") {
  REQUIRE_FALSE(is_loaded());
  std::optional<nonsep::host::PluginModel> model;
  {
    const auto plugin = nonsep::host::load_plugin(plugin_file.string(), "");
    CHECK(is_loaded());
    model = plugin.create(nlohmann::json::object());
  }
  CHECK(is_loaded());
  const double q[] = {0.5};
  double out[1];
  model->grad_V(q, out, 1);
  CHECK(out[0] == doctest::Approx(4.0 / 3.0));
  CHECK(model->plugin().name() == "evaluation_fails");
  const auto copy = *model;
  model.reset();
  CHECK(is_loaded());
  copy.grad_V(q, out, 1);
  CHECK(out[0] == doctest::Approx(4.0 / 3.0));
}

TEST_CASE("the library is unloaded when its last model is destroyed") {
  REQUIRE_FALSE(is_loaded());
  {
    const auto model = nonsep::host::load_plugin(plugin_file.string(), "").create(nlohmann::json::object());
    CHECK(is_loaded());
  }
  CHECK_FALSE(is_loaded());
}

TEST_CASE("a failed load leaves nothing loaded") {
  REQUIRE_FALSE(is_loaded());
  CHECK_THROWS_AS(nonsep::host::load_plugin(plugin_file.string(), "").create({{"no_such_parameter", 1}}),
                  nonsep::host::PluginError);
  CHECK_FALSE(is_loaded());
}

}  // namespace test_plugin_lifetime
