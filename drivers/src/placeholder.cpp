// Placeholder translation unit until the codecs land.
namespace cal::drivers {
int placeholder() { return 0; }
}  // namespace cal::drivers
