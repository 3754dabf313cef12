// main.cpp — placeholder for the `hmpm` command line.
#include <cstdio>

int main() {
  std::fputs("hmpm: not implemented yet\n", stderr);
  return 1;
}
