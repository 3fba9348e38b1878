// Fuzzes the module-type loader: the input is a module-type file (Lua returning the type table,
// see assets/modules/superbot.lua), loaded by loadModuleType from a private temporary folder.
// Bad input must end in InputError; anything else (a crash, a sanitizer report, another
// exception) is a finding.
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "script/module_type_loader.h"

namespace {

// The folder lives as long as the process (never destroyed, so the exit handler can use it).
const std::string& tempDir() {
  static const std::string* dir = [] {
    auto* d = new std::string((std::filesystem::temp_directory_path() / "rm3d-fuzz-XXXXXX").string());
    if (!mkdtemp(d->data())) std::abort();
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(tempDir(), ec);
    });
    return d;
  }();
  return *dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = tempDir() + "/fuzzed.lua";
  {
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  }
  try {
    rm3d::ModuleTypeDef def = rm3d::loadModuleType(path, RM3D_SOURCE_DIR);
    (void)def;
  } catch (const rm3d::InputError&) {
  }
  return 0;
}
