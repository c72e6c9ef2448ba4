// Runs a fuzz target over every input of its corpus folder (seeds and the inputs of fixed
// findings): a finding aborts the test.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include <gtest/gtest.h>

#include "fuzz_target.h"

TEST(FuzzCorpus, EveryInputRunsWithoutAFinding) {
  std::size_t inputs = 0;
  for (const auto& entry : std::filesystem::directory_iterator(CORPUS_DIR)) {
    std::ifstream file(entry.path(), std::ios::binary);
    const std::vector<std::uint8_t> data((std::istreambuf_iterator<char>(file)),
                                         std::istreambuf_iterator<char>());
    std::fprintf(stderr, "replaying %s\n", entry.path().c_str());  // named if it aborts
    LLVMFuzzerTestOneInput(data.data(), data.size());
    ++inputs;
  }
  EXPECT_GT(inputs, 0u) << "no corpus in " << CORPUS_DIR;
}
