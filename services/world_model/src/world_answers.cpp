#include "world_answers.hpp"

#include <algorithm>

#include "world_json.hpp"

namespace rigger::world {
namespace {

double age_seconds(Stamp stamp, Stamp now) {
  return std::max(0.0, std::chrono::duration<double>(now - stamp).count());
}

template <typename T>
QueryAnswer failure(const QueryResult<T>& r) {
  QueryAnswer a;
  a.code = std::string(to_code(r.status));
  a.message = r.message;
  return a;
}

QueryAnswer unknown(const std::string& id) {
  QueryAnswer a;
  a.code = std::string(to_code(QueryStatus::kUnknownEntity));
  a.message = "no entity \"" + id + "\"";
  return a;
}

}  // namespace

QueryAnswer answer_query(const WorldStore& store, const WorldQuery& query, Stamp now) {
  QueryAnswer a;
  try {
    switch (query.kind) {
      case QueryKind::kPose: {
        const auto r = query.feature_id.empty()
                           ? pose_of(store, query.entity_id, query.frame_id)
                           : feature_pose_of(store, query.entity_id, query.feature_id, query.frame_id);
        if (!r.ok()) return failure(r);
        a.ok = true;
        a.code = "OK";
        a.pose_frame_entity = r.value.pose_frame_entity;
        a.frame = query.frame_id;
        a.localized = r.value.all_localized && !r.value.any_stale;
        if (r.value.oldest_stamp) {
          a.stamp = *r.value.oldest_stamp;
          a.age_s = age_seconds(a.stamp, now);
        }
        a.result = {{"all_localized", r.value.all_localized}, {"any_stale", r.value.any_stale}};
        if (r.value.oldest_stamp) a.result["oldest_stamp_ns"] = to_unix_ns(*r.value.oldest_stamp);
        if (!query.feature_id.empty()) a.result["feature_id"] = query.feature_id;
        return a;
      }
      case QueryKind::kIsLocalized: {
        const auto r = is_localized(store, query.entity_id, query.max_age, now);
        if (!r.ok()) return failure(r);
        a.ok = true;
        a.code = std::string(to_code(r.value.state));
        a.message = r.value.message;
        a.localized = r.value.localized;
        if (r.value.age) a.age_s = std::chrono::duration<double>(*r.value.age).count();
        const Entity* e = store.find(query.entity_id);
        if (e && e->pose) a.stamp = e->pose->stamp;
        a.result = {{"state", a.code}, {"stale", e && e->stale}};
        return a;
      }
      case QueryKind::kFeatures: {
        const auto r = features_of(store, query.entity_id);
        if (!r.ok()) return failure(r);
        a.ok = true;
        a.code = "OK";
        a.result = features_to_json(r.value);
        return a;
      }
      case QueryKind::kEntity: {
        const Entity* e = store.find(query.entity_id);
        if (e == nullptr) return unknown(query.entity_id);
        a.ok = true;
        a.code = "OK";
        a.localized = e->localized && !e->stale;
        if (e->pose) {
          a.pose_frame_entity = e->pose->pose_parent_entity;
          a.frame = e->parent;
          a.stamp = e->pose->stamp;
          a.age_s = age_seconds(a.stamp, now);
        }
        a.result = entity_to_json(*e);
        return a;
      }
      case QueryKind::kList: {
        a.ok = true;
        a.code = "OK";
        a.result = list_entities(store, query.list_kind);
        return a;
      }
    }
  } catch (const std::exception& e) {
    // The queries do not throw by contract; a bug must still not take the world model down.
    QueryAnswer err;
    err.code = "INTERNAL";
    err.message = e.what();
    return err;
  }
  QueryAnswer err;
  err.code = "BAD_QUERY";
  err.message = "unknown query kind";
  return err;
}

}  // namespace rigger::world
