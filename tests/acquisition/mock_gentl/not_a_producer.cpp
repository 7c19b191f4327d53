// A shared library that is not a GenTL producer (it exports no GenTL function), for the
// gentl backend's "not a producer" test.
extern "C" __attribute__((visibility("default"))) int tomorig_not_a_producer() { return 42; }
