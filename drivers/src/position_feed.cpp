// Placeholder: codec arrives with the drivers issue.
namespace cal::drivers::codec {
int position_feed_placeholder() { return 0; }
}  // namespace cal::drivers::codec
