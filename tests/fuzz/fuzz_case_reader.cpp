// libFuzzer target for the case reader: any byte string given as a case file (and as a --set
// override) must yield a Case/Model or a CaseError, never a crash, hang or leak.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "rfem/cases/case_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = "/tmp/rfem_fuzz_" + std::to_string(getpid()) + ".toml";
  const std::string text(reinterpret_cast<const char*>(data), size);
  // The first line, if it looks like key=value, doubles as an override.
  std::vector<std::string> overrides;
  const auto nl = text.find('\n');
  if (nl != std::string::npos && nl < 80 && text.find('=') < nl) overrides.push_back(text.substr(0, nl));
  if (FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fwrite(text.data(), 1, text.size(), f);
    std::fclose(f);
  }
  try {
    const rfem::Case c = rfem::read_case(path, overrides);
    // Keep models small: the fuzzer is after the reader, not big allocations.
    int parts = 0, n = 0;
    for (const auto& l : c.links) {
      n += l.n;
      for (const auto& s : l.link.segments) parts += s.parts;
    }
    if (n <= 64 && parts <= 64) rfem::build_model(c);
  } catch (const rfem::CaseError&) {
  }
  return 0;
}
