#ifndef OB_TEST_CONSTS
#define OB_TEST_CONSTS
const float OB_ONE = 1.0;
#endif
