// Runs a fuzz target over its corpus folder (seeds and the inputs of fixed findings) and the
// shipped scenes, which scripts/fuzz.sh gives fuzz_scene as seeds. A finding aborts the test,
// so a harness that cannot pass its own seeds fails here and not only under libFuzzer. (To
// fuzz_world a scene is mere bytes: cheap to replay, but too long to fuzz from.)
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include <gtest/gtest.h>

#include "fuzz_target.h"

namespace {

// CORPUS_DIR is <package>/test/fuzz/corpus/<target>.
const std::filesystem::path kCorpus = CORPUS_DIR;
const std::filesystem::path kScenes =
    kCorpus.parent_path().parent_path().parent_path().parent_path() / "config" / "scenes";

// Replays every file of `folder`; how many there were.
std::size_t replayFolder(const std::filesystem::path& folder) {
  std::size_t inputs = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    std::ifstream file(entry.path(), std::ios::binary);
    const std::vector<std::uint8_t> data((std::istreambuf_iterator<char>(file)),
                                         std::istreambuf_iterator<char>());
    std::fprintf(stderr, "replaying %s\n", entry.path().c_str());  // named if it aborts
    LLVMFuzzerTestOneInput(data.data(), data.size());
    ++inputs;
  }
  return inputs;
}

}  // namespace

TEST(FuzzCorpus, EveryInputRunsWithoutAFinding) {
  EXPECT_GT(replayFolder(kCorpus), 0u) << "no corpus in " << kCorpus;
}

TEST(FuzzCorpus, EveryShippedSceneRunsWithoutAFinding) {
  EXPECT_GT(replayFolder(kScenes), 0u) << "no scenes in " << kScenes;
}
