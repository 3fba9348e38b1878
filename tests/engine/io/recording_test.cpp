// The recording reader's size checks: a size field is checked against the bytes the file really
// has before anything is allocated.
#include "io/recording.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

namespace {

/// A file of the 16-byte header, one chunk header (tag, crc, raw size, packed size) and `pad`
/// zero bytes.
std::string writeClaim(const char* name, uint64_t rawSize, uint64_t packedSize, size_t pad) {
  const std::string path =
      (std::filesystem::temp_directory_path() / (name + std::to_string(getpid()) + ".rec")).string();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  const uint32_t version = 1, reserved = 0, crc = 0;
  std::fwrite("RM3DREC\n", 1, 8, f);
  std::fwrite(&version, 4, 1, f);
  std::fwrite(&reserved, 4, 1, f);
  std::fwrite("META", 1, 4, f);
  std::fwrite(&crc, 4, 1, f);
  std::fwrite(&rawSize, 8, 1, f);
  std::fwrite(&packedSize, 8, 1, f);
  for (size_t i = 0; i < pad; ++i) std::fputc(0, f);
  std::fclose(f);
  return path;
}

}  // namespace

TEST_CASE("a 1.5 KB recording whose chunk claims 4 GB is refused before anything is allocated") {
  rm3d::Recording rec;
  std::string err;
  const std::string packed = writeClaim("rm3d_claim_packed", 4000000000ull, 4000000000ull, 1500);
  CHECK_FALSE(rec.load(packed, err));
  CHECK(err ==
        packed +
            ": truncated recording (the META chunk at byte 16 claims 4000000000 bytes, the file has 1500 "
            "left; was the run killed?)");
  std::remove(packed.c_str());
  // A small packed size that would unpack to 4 GB: past zlib's 1032:1, so impossible.
  const std::string raw = writeClaim("rm3d_claim_raw", 4000000000ull, 100, 1500);
  CHECK_FALSE(rec.load(raw, err));
  CHECK(err == raw + ": damaged recording (a chunk at byte 16 has impossible sizes)");
  std::remove(raw.c_str());
}
