// A ROS 2 bag (formats/mcap_reader.h) as the table of a column map's sources (DESIGN.md "ROS 2 bags
// (MCAP) in and out"): one column per distinct `from` of the map, named by it, one row per message of
// t's topic; ApplyColumnMap then takes the table as it takes a foreign CSV.
#pragma once
#include <memory>
#include <string>

#include "formats/column_map.h"
#include "formats/csv_table.h"
#include "formats/mcap_reader.h"
#include "formats/ros2msg.h"

namespace exotwin {

// The decoder of one channel's messages: CDR by its ros2msg schema (parsed once), or JSON. Throws
// InputError ("<context>: topic T of <bag> holds messages encoded ...") for another encoding, and
// what Ros2MsgSchema throws for a schema that does not parse.
class ChannelDecoder {
 public:
  ChannelDecoder(const McapChannel& channel, const std::string& bag, const std::string& context);
  // The message as a tree; InputError naming `where` for bytes its type does not decode.
  MsgValue operator()(const McapMessage& m, const std::string& where) const;

 private:
  std::shared_ptr<const Ros2MsgSchema> schema_;  // null: JSON
};

// The map's sources read from the bag at `path` (an .mcap file or a rosbag2 folder):
//   `TOPIC.path.to.field`, `TOPIC.array[N]`, `TOPIC.array[NAME]` (NAME's index in the message's
//   `name` array beside `array`): a number in each message (formats/ros2msg.h decodes CDR with the
//   channel's ros2msg schema, or JSON);
//   t's source: `TOPIC.header.stamp` (a time: sec + nanosec), `TOPIC.log_time` or `TOPIC.publish_time`
//   (the MCAP message's times). t = (time - the first message's time) in int64 ns, then / 1e9 s.
// The rows are t's topic's messages in the bag's order; a source on another topic is interpolated
// linearly (Interpolate: held at the ends) onto t's times, its messages placed by their
// header.stamp when t is a header.stamp and they have one, else by log_time (publish_time when t is
// publish_time). row r's "line" (line_of_row) is the message's 1-based number on t's topic.
// Throws InputError naming the bag and the map's line for a topic the bag lacks (its topics listed),
// a message encoding it cannot decode, and, naming the message (its byte offset, topic and number),
// for a field a message lacks, a NAME absent from its `name` array, a value that is not a number, a
// time that is not one, another topic's times not increasing.
CsvTable BagTable(const std::string& path, const ColumnMap& map);

}  // namespace exotwin
