// salient-sim: a simulated Marlin printer behind a pseudo-terminal (Step 5 builds it out).
#include <cstdio>
#include <cstring>

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--version") == 0) {
      std::printf("salient-sim 0.1.0\n");
      return 0;
    }
  }
  std::fprintf(stderr, "salient-sim: not yet: the simulated printer arrives with the printer link (step 5)\n");
  return 2;
}
