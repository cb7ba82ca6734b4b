// Placeholder: the capture file format arrives with the drivers issue.
namespace cal::replay {
int placeholder() { return 0; }
}  // namespace cal::replay
