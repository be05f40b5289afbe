#include "formats/bag_table.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>

#include "core/error.h"
#include "core/file_text.h"
#include "formats/mcap_format.h"
#include "formats/measured_data.h"

namespace exotwin {
namespace {

// How a topic's messages are placed in time.
enum class TimeOf { kStamp, kLogTime, kPublishTime };

// One source of the map: a topic and a field path.
struct Source {
  std::string from;     // as the map gives it (the table's column name)
  std::string context;  // "MAP: columns.q_hip.from (line 3)"
  int channel = -1;
  FieldPath path;
};

// A time (builtin_interfaces/Time: sec + nanosec; nsec as Foxglove's JSON writes it) in ns.
bool StampNs(const MsgValue& v, int64_t* ns) {
  const MsgValue* sec = v.Field("sec");
  const MsgValue* nsec = v.Field("nanosec");
  if (!nsec) nsec = v.Field("nsec");
  if (!sec || !nsec || (sec->kind != MsgValue::kInt && sec->kind != MsgValue::kUint) ||
      (nsec->kind != MsgValue::kInt && nsec->kind != MsgValue::kUint))
    return false;
  const int64_t s = sec->kind == MsgValue::kInt ? sec->i : static_cast<int64_t>(std::min<uint64_t>(sec->u, 1ull << 62));
  const int64_t n = nsec->kind == MsgValue::kInt ? nsec->i : static_cast<int64_t>(std::min<uint64_t>(nsec->u, 1ull << 62));
  constexpr int64_t kMaxSec = std::numeric_limits<int64_t>::max() / 1000000000 - 1;
  if (s > kMaxSec || s < -kMaxSec || n < 0 || n >= 1000000000) return false;
  *ns = s * 1000000000 + n;
  return true;
}

// The time of message `m` (decoded as `v`) by `how`; `stamp`: the path of header.stamp.
int64_t TimeNs(const McapMessage& m, const MsgValue& v, TimeOf how, const FieldPath& stamp, const std::string& where) {
  if (how == TimeOf::kLogTime || how == TimeOf::kPublishTime) {
    const uint64_t t = how == TimeOf::kLogTime ? m.log_time : m.publish_time;
    if (t > static_cast<uint64_t>(std::numeric_limits<int64_t>::max()))
      throw InputError(where + ": " + (how == TimeOf::kLogTime ? "log_time " : "publish_time ") + std::to_string(t) +
                       " ns is beyond the year 2262, expected a time in ns since the epoch");
    return static_cast<int64_t>(t);
  }
  int64_t ns = 0;
  if (!StampNs(ResolveField(v, stamp, where), &ns))
    throw InputError(where + ": " + stamp.text + " is not a time, expected sec and nanosec (0 <= nanosec < 1e9)");
  return ns;
}

// True when the source `from` is a field of `topic`: "TOPIC.field...".
bool Names(const std::string& from, const std::string& topic) {
  return !topic.empty() && from.size() > topic.size() + 1 && from.compare(0, topic.size(), topic) == 0 &&
         from[topic.size()] == '.';
}

double Seconds(int64_t ns, int64_t origin) { return static_cast<double>(ns - origin) / 1e9; }

}  // namespace

ChannelDecoder::ChannelDecoder(const McapChannel& c, const std::string& bag, const std::string& context) {
  const std::string topic = ShownText(c.topic);
  if (c.message_encoding == mcap::kMessageEncodingCdr && c.schema.encoding == mcap::kSchemaEncodingRos2Msg) {
    schema_ = std::make_shared<Ros2MsgSchema>(c.schema.name, c.schema.data,
                                              bag + ": topic " + topic + ": schema " + ShownText(c.schema.name));
  } else if (c.message_encoding != mcap::kMessageEncodingJson) {
    throw InputError(context + ": topic " + topic + " of " + bag + " holds messages encoded '" +
                     ShownText(c.message_encoding) + "' (schema encoding '" + ShownText(c.schema.encoding) +
                     "'), expected cdr with a ros2msg schema, or json");
  }
}

MsgValue ChannelDecoder::operator()(const McapMessage& m, const std::string& where) const {
  return schema_ ? schema_->Decode(m.data, where) : DecodeJsonMessage(m.data, where);
}

CsvTable BagTable(const std::string& path, const ColumnMap& map) {
  // Only the messages of topics a source names are kept (a bag's camera topics are not copied).
  const McapRecord bag = ReadMcapRecord(path, [&map](const std::string& topic) {
    return std::any_of(map.columns.begin(), map.columns.end(), [&](const ColumnSpec& s) { return Names(s.from, topic); });
  });
  // The sources: the longest topic of the bag that `from` starts with, then the field path.
  std::vector<Source> sources;
  TimeOf t_how = TimeOf::kStamp;
  for (const ColumnSpec& s : map.columns) {
    if (std::any_of(sources.begin(), sources.end(), [&](const Source& o) { return o.from == s.from; })) continue;
    Source src;
    src.from = s.from;
    src.context = map.source + ": columns." + s.target + ".from (line " + std::to_string(s.line) + ")";
    size_t best = 0;
    for (size_t c = 0; c < bag.channels.size(); ++c) {
      const std::string& topic = bag.channels[c].topic;
      if (topic.size() > best && Names(s.from, topic)) best = topic.size(), src.channel = static_cast<int>(c);
    }
    if (src.channel < 0) {
      std::string topics;
      for (const McapChannel& c : bag.channels) topics += (topics.empty() ? "" : ", ") + ShownText(c.topic);
      throw InputError(src.context + ": '" + s.from + "' names no topic of " + path + " (its topics: " +
                       (topics.empty() ? "none" : topics) + "), expected TOPIC.field");
    }
    src.path = ParseFieldPath(s.from.substr(best + 1), src.context);
    if (s.target == "t") {
      const std::string p = src.path.text;
      t_how = p == "log_time" ? TimeOf::kLogTime : p == "publish_time" ? TimeOf::kPublishTime : TimeOf::kStamp;
    }
    sources.push_back(std::move(src));
  }
  const Source& t_src = sources.front();  // ReadColumnMap puts t first
  const int t_channel = t_src.channel;
  const FieldPath header_stamp = ParseFieldPath("header.stamp", "header.stamp");
  const FieldPath& t_stamp = t_how == TimeOf::kStamp ? t_src.path : header_stamp;

  // Per channel: its messages' times and the values of its sources.
  std::map<int, std::vector<size_t>> of_channel;  // channel -> indexes of its sources
  of_channel[t_channel];
  for (size_t k = 1; k < sources.size(); ++k) of_channel[sources[k].channel].push_back(k);
  std::vector<std::vector<double>> values(sources.size());
  std::vector<int> line_of_row;
  std::vector<int64_t> t_ns;
  std::map<int, std::vector<int64_t>> times;
  for (auto& [channel, ks] : of_channel) {
    const McapChannel& c = bag.channels[channel];
    const std::string topic = ShownText(c.topic);
    const bool is_t = channel == t_channel;
    TimeOf how = t_how;
    // t's topic placed by log_time or publish_time with no other source on it is not decoded (its
    // messages may be of any encoding).
    std::optional<ChannelDecoder> decode;
    if (!ks.empty() || how == TimeOf::kStamp) decode.emplace(c, path, sources[ks.empty() ? 0 : ks.front()].context);
    bool first = true;
    size_t number = 0;
    std::vector<int64_t>& ns = is_t ? t_ns : times[channel];
    for (const McapMessage& m : bag.messages) {
      if (m.channel != static_cast<size_t>(channel)) continue;
      ++number;
      const std::string where = m.where + ": topic " + topic + ", message " + std::to_string(number);
      const MsgValue v = decode ? (*decode)(m, where) : MsgValue();
      if (first && !is_t && how == TimeOf::kStamp) {
        const MsgValue* h = v.Field("header");
        if (!h || !h->Field("stamp")) how = TimeOf::kLogTime;  // no stamp of its own: placed by log_time
      }
      first = false;
      ns.push_back(TimeNs(m, v, how, is_t ? t_stamp : header_stamp, where));
      if (is_t) line_of_row.push_back(static_cast<int>(std::min<size_t>(number, std::numeric_limits<int>::max())));
      for (size_t k : ks) {
        const MsgValue& x = ResolveField(v, sources[k].path, where);
        if (!x.IsNumber())
          throw InputError(where + ": " + sources[k].path.text + " is " +
                           (x.kind == MsgValue::kString ? "a string" : x.kind == MsgValue::kArray ? "an array"
                            : x.kind == MsgValue::kStruct ? "a message (its fields: " + x.FieldNames() + ")"
                                                          : "null") +
                           ", expected a number (" + sources[k].context + ")");
        values[k].push_back(x.Number());
      }
    }
    if (number == 0)
      throw InputError(sources[ks.empty() ? 0 : ks.front()].context + ": topic " + topic + " of " + path +
                       " holds no message");
    if (!is_t)
      for (size_t r = 1; r < ns.size(); ++r)
        if (ns[r] <= ns[r - 1])
          throw InputError(path + ": topic " + topic + ", message " + std::to_string(r + 1) + ": its time " +
                           std::to_string(ns[r]) + " ns is not after message " + std::to_string(r) + "'s (" +
                           std::to_string(ns[r - 1]) + " ns), expected increasing times to interpolate " +
                           (how == TimeOf::kStamp ? "header.stamp" : how == TimeOf::kLogTime ? "log_time" : "publish_time"));
  }
  const int64_t origin = t_ns.front();
  CsvTable table;
  table.line_of_row = std::move(line_of_row);
  std::vector<double> t(t_ns.size());
  for (size_t r = 0; r < t.size(); ++r) t[r] = Seconds(t_ns[r], origin);
  for (size_t k = 0; k < sources.size(); ++k) {
    table.names.push_back(sources[k].from);
    if (k == 0) {
      table.columns.push_back(t);
    } else if (sources[k].channel == t_channel) {
      table.columns.push_back(std::move(values[k]));
    } else {
      const std::vector<int64_t>& ns = times[sources[k].channel];
      std::vector<double> x(ns.size());
      for (size_t r = 0; r < x.size(); ++r) x[r] = Seconds(ns[r], origin);
      table.columns.push_back(Interpolate(x, values[k], t));
    }
  }
  return table;
}

}  // namespace exotwin
