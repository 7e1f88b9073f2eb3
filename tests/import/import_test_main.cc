// import_tests' main: GoogleTest plus --update-golden (rewrites
// tests/import/golden/, as golden_tests does for tests/golden/).
#include <string>

#include <gtest/gtest.h>

namespace substratec::importtest {
bool gUpdateGolden = false;
}

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--update-golden") substratec::importtest::gUpdateGolden = true;
  return RUN_ALL_TESTS();
}
