// CDR encoding of the ROS 2 messages exotwin writes: see cdr_writer.h.
#include "formats/cdr_writer.h"

#include <cstring>

namespace exotwin::cdr {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "CdrWriter copies the host's little-endian values");

void CdrWriter::Reset() { buf_.assign({0x00, 0x01, 0x00, 0x00}); }

void CdrWriter::Align(size_t n) {
  const size_t pos = buf_.size() - 4;  // counted from the end of the encapsulation header
  if (pos % n) buf_.resize(buf_.size() + n - pos % n, 0);
}

void CdrWriter::Primitive(const void* v, size_t n) {
  Align(n);
  const size_t at = buf_.size();
  buf_.resize(at + n);
  std::memcpy(buf_.data() + at, v, n);
}

void CdrWriter::String(const std::string& v) {
  Uint32(static_cast<uint32_t>(v.size() + 1));
  buf_.insert(buf_.end(), v.begin(), v.end());
  buf_.push_back(0);
}

size_t CdrWriter::Float64Sequence(const double* v, size_t n) {
  Uint32(static_cast<uint32_t>(n));
  if (n == 0) return 0;
  Align(8);
  const size_t at = buf_.size();
  buf_.resize(at + 8 * n);
  std::memcpy(buf_.data() + at, v, 8 * n);
  return at;
}

void CdrWriter::StringSequence(const std::vector<std::string>& v) {
  Uint32(static_cast<uint32_t>(v.size()));
  for (const std::string& s : v) String(s);
}

namespace {

void SecondsAndNanoseconds(int64_t ns, int32_t* sec, uint32_t* nanosec) {
  int64_t s = ns / 1000000000, rest = ns % 1000000000;
  if (rest < 0) rest += 1000000000, --s;
  *sec = static_cast<int32_t>(s);
  *nanosec = static_cast<uint32_t>(rest);
}

}  // namespace

void Time(CdrWriter& w, int64_t ns) {
  int32_t sec;
  uint32_t nanosec;
  SecondsAndNanoseconds(ns, &sec, &nanosec);
  w.Int32(sec);
  w.Uint32(nanosec);
}

void PatchTime(uint8_t* at, int64_t ns) {  // sec at 0, nanosec at 4: both 4-aligned, as Time writes them
  int32_t sec;
  uint32_t nanosec;
  SecondsAndNanoseconds(ns, &sec, &nanosec);
  std::memcpy(at, &sec, 4);
  std::memcpy(at + 4, &nanosec, 4);
}

void PatchFloat64s(uint8_t* at, const double* v, size_t n) { std::memcpy(at, v, 8 * n); }

JointStateLayout JointState(CdrWriter& w, int64_t stamp_ns, const std::string& frame_id,
                            const std::vector<std::string>& names, const double* position, const double* velocity,
                            const double* effort, size_t n) {
  JointStateLayout l;
  l.stamp = w.bytes().size();  // 4: right after the encapsulation header, aligned
  Time(w, stamp_ns);
  w.String(frame_id);
  w.StringSequence(names);
  l.position = w.Float64Sequence(position, position ? n : 0);
  l.velocity = w.Float64Sequence(velocity, velocity ? n : 0);
  l.effort = w.Float64Sequence(effort, effort ? n : 0);
  return l;
}

size_t Float64MultiArray(CdrWriter& w, const std::string& label, const double* data, size_t n) {
  w.Uint32(1);  // layout.dim: one dimension
  w.String(label);
  w.Uint32(static_cast<uint32_t>(n));  // size
  w.Uint32(static_cast<uint32_t>(n));  // stride
  w.Uint32(0);                         // layout.data_offset
  return w.Float64Sequence(data, n);
}

const char* const kJointStateType = "sensor_msgs/msg/JointState";
const char* const kFloat64MultiArrayType = "std_msgs/msg/Float64MultiArray";

namespace {

const char* const kSeparator = "\n================================================================================\n";

// The .msg files of ROS 2's common_interfaces (sensor_msgs, std_msgs) and rcl_interfaces
// (builtin_interfaces), as rosbag2 embeds them.
const char* const kTimeMsg =
    "# This message communicates ROS Time, which is defined here:\n"
    "# https://design.ros2.org/articles/clock_and_time.html\n"
    "\n"
    "# The seconds component, valid over all int32 values.\n"
    "int32 sec\n"
    "\n"
    "# The nanoseconds component, valid in the range [0, 10e9).\n"
    "uint32 nanosec\n";

const char* const kHeaderMsg =
    "# Standard metadata for higher-level stamped data types.\n"
    "# This is generally used to communicate timestamped data\n"
    "# in a particular coordinate frame.\n"
    "\n"
    "# Two-integer timestamp that is expressed as seconds and nanoseconds.\n"
    "builtin_interfaces/Time stamp\n"
    "\n"
    "# Transform frame with which this data is associated.\n"
    "string frame_id\n";

const char* const kJointStateMsg =
    "# This is a message that holds data to describe the state of a set of torque controlled joints.\n"
    "#\n"
    "# The state of each joint (revolute or prismatic) is defined by:\n"
    "#  * the position of the joint (rad or m),\n"
    "#  * the velocity of the joint (rad/s or m/s) and\n"
    "#  * the effort that is applied in the joint (Nm or N).\n"
    "#\n"
    "# Each joint is uniquely identified by its name\n"
    "# The header specifies the time at which the joint states were recorded. All the joint states\n"
    "# in one message have to be recorded at the same time.\n"
    "#\n"
    "# This message consists of a multiple arrays, one for each part of the joint state.\n"
    "# The goal is to make each of the fields optional. When e.g. your joints have no\n"
    "# effort associated with them, you can leave the effort array empty.\n"
    "#\n"
    "# All arrays in this message should have the same size, or be empty.\n"
    "# This is the only way to uniquely associate the joint name with the correct\n"
    "# states.\n"
    "\n"
    "std_msgs/Header header\n"
    "\n"
    "string[] name\n"
    "float64[] position\n"
    "float64[] velocity\n"
    "float64[] effort\n";

const char* const kFloat64MultiArrayMsg =
    "# This was originally provided as an example message.\n"
    "# It is deprecated as of Foxy\n"
    "# It is recommended to create your own semantically meaningful message.\n"
    "# However if you would like to continue using this please use the equivalent in example_msgs.\n"
    "\n"
    "# Please look at the MultiArrayLayout message definition for\n"
    "# documentation on all multiarrays.\n"
    "\n"
    "MultiArrayLayout  layout        # specification of data layout\n"
    "float64[]         data          # array of data\n";

const char* const kMultiArrayLayoutMsg =
    "# This was originally provided as an example message.\n"
    "# It is deprecated as of Foxy\n"
    "# It is recommended to create your own semantically meaningful message.\n"
    "# However if you would like to continue using this please use the equivalent in example_msgs.\n"
    "\n"
    "# The multiarray declares a generic multi-dimensional array of a\n"
    "# particular data type.  Dimensions are ordered from outer most\n"
    "# to inner most.\n"
    "#\n"
    "# Accessors should ALWAYS be written in terms of dimension stride\n"
    "# and specified outer-most dimension first.\n"
    "#\n"
    "# multiarray(i,j,k) = data[data_offset + dim_stride[1]*i + dim_stride[2]*j + k]\n"
    "#\n"
    "# A standard, 3-channel 640x480 image with interleaved color channels\n"
    "# would be specified as:\n"
    "#\n"
    "# dim[0].label  = \"height\"\n"
    "# dim[0].size   = 480\n"
    "# dim[0].stride = 3*640*480 = 921600  (note dim[0] stride is just size of image)\n"
    "# dim[1].label  = \"width\"\n"
    "# dim[1].size   = 640\n"
    "# dim[1].stride = 3*640 = 1920\n"
    "# dim[2].label  = \"channel\"\n"
    "# dim[2].size   = 3\n"
    "# dim[2].stride = 3\n"
    "#\n"
    "# The stride of dimension 0 is the total number of elements in the array.\n"
    "\n"
    "MultiArrayDimension[] dim # Array describing the dimensions of the data.\n"
    "uint32 data_offset        # padding elements at front of data\n";

const char* const kMultiArrayDimensionMsg =
    "# This was originally provided as an example message.\n"
    "# It is deprecated as of Foxy\n"
    "# It is recommended to create your own semantically meaningful message.\n"
    "# However if you would like to continue using this please use the equivalent in example_msgs.\n"
    "\n"
    "string label   # label of given dimension\n"
    "uint32 size    # size of given dimension (in type units)\n"
    "uint32 stride  # stride of given dimension\n";

std::string Dependency(const char* name, const char* text) {
  return std::string(kSeparator) + "MSG: " + name + "\n" + text;
}

}  // namespace

const std::string& JointStateDefinition() {
  static const std::string d = std::string(kJointStateMsg) + Dependency("std_msgs/Header", kHeaderMsg) +
                               Dependency("builtin_interfaces/Time", kTimeMsg);
  return d;
}

const std::string& Float64MultiArrayDefinition() {
  static const std::string d = std::string(kFloat64MultiArrayMsg) +
                               Dependency("std_msgs/MultiArrayLayout", kMultiArrayLayoutMsg) +
                               Dependency("std_msgs/MultiArrayDimension", kMultiArrayDimensionMsg);
  return d;
}

}  // namespace exotwin::cdr
