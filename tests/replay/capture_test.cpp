#include <gtest/gtest.h>
// Placeholder until the capture format lands: the library links.
namespace cal::replay {
int placeholder();
}
TEST(CapturePlaceholder, Links) { EXPECT_EQ(cal::replay::placeholder(), 0); }
