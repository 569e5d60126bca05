// Test fixture: an included file whose function has a deliberate error on line 5, so that the
// test can check that the driver's error is mapped to this file, not to the file including it.

float helper(float x) {
    return x * undeclared_in_helper;
}
