// Placeholder: codec arrives with the drivers issue.
namespace cal::drivers::codec {
int line_gauge_placeholder() { return 0; }
}  // namespace cal::drivers::codec
