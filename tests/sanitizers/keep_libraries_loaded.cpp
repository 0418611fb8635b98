// Linked into every executable of a MOTES_SANITIZE build (cmake/MotesWarnings.cmake), never into a
// normal one. LeakSanitizer reports leaks at exit, after the Vulkan loader has unloaded its drivers
// (vkDestroyInstance calls dlclose on lavapipe and libLLVM). The stack frames of an allocation made
// inside an unloaded library then have no module name ("<unknown module>"), so the suppressions in
// lsan.supp, which name libraries, cannot match them; and memory a driver still referenced from its
// own globals turns into a "leak" once those globals are unmapped. Keeping every library loaded
// until the process ends (a dlclose that does nothing) leaves both as they are: allocations
// reachable from a driver's globals stay reachable, and what is reported names its library. motes's
// own memory is checked exactly as before (tests/sanitizers/leak_canary.cpp proves it).
extern "C" int dlclose(void* /*handle*/) { return 0; }
