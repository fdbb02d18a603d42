// The program that owns the test files' precompiled header
// (tests/CMakeLists.txt, DIFFPD_TEST_PRECOMPILED): CMake compiles the header
// with this program's flags, which are every test program's, and the tests
// reuse it. It is built, never run.
int main() { return 0; }
