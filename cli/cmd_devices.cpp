// dpoint devices [--json]: the Vulkan devices seen, with what each precision mode needs
// (DESIGN §1, §4) and the result of the emulated-double self-test on each.
#include <cstdio>
#include <memory>

#include "cli/cli_text.h"
#include "cli/commands.h"
#include "core/memory.h"
#include "vulkan/context.h"
#include "viewer/selftest.h"

namespace dpoint {
namespace {

struct DeviceReport {
  DeviceFacts facts;
  std::string self_test;  // "pass", "FAIL: …" or why it could not run
  std::vector<std::string> modes;
};

DeviceReport examine(const DeviceFacts& facts) {
  DeviceReport report{facts, "", {}};
  SelfTest self_test;
  Result<std::unique_ptr<VulkanContext>> context = VulkanContext::create(ContextOptions{std::to_string(facts.index), false});
  if (!context) {
    report.self_test = "not run: " + context.error().message;
    return report;
  }
  Result<SelfTest> ran = runPrecisionSelfTest(**context);
  if (!ran) {
    report.self_test = "not run: " + ran.error().message;
  } else {
    self_test = *ran;
    report.self_test = ran->low_parts_survive ? "pass" : "FAIL: " + ran->detail;
  }
  for (PrecisionMode mode : kAllModes)
    if (modeUsable(**context, mode, self_test, false)) report.modes.emplace_back(modeName(mode));
  return report;
}

int runDevices(bool json) {
  Result<std::vector<DeviceFacts>> devices = listDevices();
  if (!devices) return reportError(devices.error());
  std::vector<DeviceReport> reports;
  for (const DeviceFacts& f : *devices) reports.push_back(examine(f));
  if (json) {
    std::printf("[\n");
    for (size_t i = 0; i < reports.size(); ++i) {
      const DeviceReport& r = reports[i];
      const DeviceFacts& f = r.facts;
      std::string modes;
      for (const std::string& m : r.modes) modes += (modes.empty() ? "" : ", ") + jsonString(m);
      std::printf("  {\"index\": %u, \"name\": %s, \"type\": %s, \"api_version\": %s, \"driver\": %s, "
                  "\"driver_version\": %s, \"shader_float64\": %s, \"r64g64b64_vertex\": %s, "
                  "\"vertex_stores\": %s, \"max_storage_buffer_range\": %llu, \"max_memory_allocation\": %llu, "
                  "\"timestamp_period_ns\": %s, \"self_test\": %s, \"modes\": [%s]}%s\n",
                  f.index, jsonString(f.name).c_str(), jsonString(f.type).c_str(),
                  jsonString(formatApiVersion(f.api_version)).c_str(),
                  jsonString(f.driver_name + " " + f.driver_info).c_str(),
                  jsonString(formatDriverVersion(f.vendor_id, f.driver_version)).c_str(),
                  f.shader_float64 ? "true" : "false", f.r64g64b64_vertex ? "true" : "false",
                  f.vertex_stores ? "true" : "false", static_cast<unsigned long long>(f.max_storage_buffer_range),
                  static_cast<unsigned long long>(f.max_memory_allocation),
                  formatNumber(f.timestamp_period_ns, true).c_str(), jsonString(r.self_test).c_str(), modes.c_str(),
                  i + 1 < reports.size() ? "," : "");
    }
    std::printf("]\n");
    return 0;
  }
  for (const DeviceReport& r : reports) {
    const DeviceFacts& f = r.facts;
    std::string modes;
    for (const std::string& m : r.modes) modes += (modes.empty() ? "" : " ") + m;
    std::printf("%u: %s (%s), Vulkan %s, driver %s %s (%s)\n", f.index, f.name.c_str(), f.type.c_str(),
                formatApiVersion(f.api_version).c_str(), f.driver_name.c_str(), f.driver_info.c_str(),
                formatDriverVersion(f.vendor_id, f.driver_version).c_str());
    std::printf("   shaderFloat64 %s, R64G64B64 vertex input %s, vertex stores %s, storage range %s, "
                "allocation %s, timestamps %s\n",
                f.shader_float64 ? "yes" : "no", f.r64g64b64_vertex ? "yes" : "no (native pulls)",
                f.vertex_stores ? "yes" : "no", formatBytes(f.max_storage_buffer_range).c_str(),
                formatBytes(f.max_memory_allocation).c_str(), f.timestamp_period_ns > 0 ? "yes" : "no");
    std::printf("   df64 self-test: %s\n   modes: %s\n", r.self_test.c_str(), modes.c_str());
  }
  return 0;
}

}  // namespace

void addDevicesCommand(CLI::App& app, RunCommand& run) {
  auto json = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand("devices", "List the Vulkan devices, the features each precision mode needs, and "
                                                "the result of the emulated-double self-test");
  cmd->add_flag("--json", *json, "Print JSON");
  cmd->callback([json, &run]() { run = [json]() { return runDevices(*json); }; });
}

}  // namespace dpoint
