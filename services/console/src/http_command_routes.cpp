// The console's command routes: publishing a recipe and resuming a task (two steps: select, then
// confirm), pausing, stopping and cancelling a task, answering an operator prompt.
#include <algorithm>

#include <httplib.h>

#include "http_api.hpp"
#include "http_replies.hpp"

namespace rigger::console {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

void HttpApi::post_recipe(const httplib::Request& req, httplib::Response& res) {
  auto user = who(req, res, Role::kProgrammer);
  if (!user) return;
  auto recipe = body(req, res);
  if (!recipe) return;
  if (!recipe->contains("task_id") || !(*recipe)["task_id"].is_string() || (*recipe)["task_id"].get<std::string>().empty())
    return send_error(res, 400, "the recipe needs a non-empty string task_id", req.path + "#/task_id");
  const std::string task_id = (*recipe)["task_id"];
  const std::string id = new_confirmation({user->name, "publish", task_id, req.body, Clock::now() + config_.confirm_timeout});
  audit(*user, "select publish", task_id, "awaiting confirmation " + id);
  send_json(res, {{"confirmation_id", id}, {"action", "publish " + task_id},
                  {"expires_in_s", std::chrono::duration<double>(config_.confirm_timeout).count()}}, 202);
}

void HttpApi::post_task_resume(const httplib::Request& req, httplib::Response& res) {
  auto user = who(req, res, Role::kProgrammer);
  if (!user) return;
  const std::string task_id = req.matches[1];
  const std::string id = new_confirmation({user->name, "resume", task_id, "", Clock::now() + config_.confirm_timeout});
  audit(*user, "select resume", task_id, "awaiting confirmation " + id);
  send_json(res, {{"confirmation_id", id}, {"action", "resume " + task_id},
                  {"expires_in_s", std::chrono::duration<double>(config_.confirm_timeout).count()}}, 202);
}

void HttpApi::post_confirm(const httplib::Request& req, httplib::Response& res) {
  auto user = who(req, res, Role::kViewer);
  if (!user) return;
  auto b = body(req, res);
  if (!b) return;
  const std::string id = text_field(*b, "confirmation_id");
  Pending p;
  {
    std::lock_guard lock(pending_mutex_);
    auto it = pending_.find(id);
    if (it == pending_.end() || it->second.user != user->name) {
      audit(*user, "confirm", id, "refused: unknown");
      return send_error(res, 409, "no pending action " + id + " of user " + user->name + " (already confirmed, or never selected)", req.path);
    }
    p = it->second;
    pending_.erase(it);
  }
  if (Clock::now() > p.deadline) {
    audit(*user, "confirm " + p.kind, p.task_id, "refused: expired");
    return send_error(res, 409,
                      "the confirmation of " + p.kind + " " + p.task_id + " expired (confirm within " +
                          std::to_string(config_.confirm_timeout.count() / 1000.0).substr(0, 4) + " s); select again",
                      req.path);
  }
  // Only programmers can have selected these; check again in case of a changed users file.
  if (static_cast<int>(user->role) < static_cast<int>(Role::kProgrammer))
    return send_error(res, 403, "only a programmer may " + p.kind, req.path);
  if (p.kind == "cell") return confirm_cell(*user, p, req, res);
  const auto r = p.kind == "publish"
                     ? backend_.publish_recipe(p.task_id, p.payload, "console:" + user->name)
                     : backend_.task_command(p.task_id, "resume", "resumed by " + user->name + " at the console",
                                             "console:" + user->name);
  audit(*user, p.kind, p.task_id, r.ok ? "sent" : "failed: " + r.message);
  if (!r.ok) return send_error(res, 503, r.message, req.path);
  send_json(res, {{"done", p.kind}, {"task_id", p.task_id}});
}

void HttpApi::task_command(const httplib::Request& req, httplib::Response& res, const std::string& kind, Role needed) {
  auto user = who(req, res, needed);
  if (!user) return;
  auto b = body(req, res);
  if (!b) return;
  const std::string task_id = req.matches[1];
  if (state_.task(task_id).is_null()) return send_error(res, 404, "no task " + task_id + " known", req.path);
  std::string reason = text_field(*b, "reason");
  const std::string wire_kind = kind == "stop" ? "cancel" : kind;
  reason = (kind == "stop" ? "STOP" : kind) + std::string(" by ") + user->name + " at the console" +
           (reason.empty() ? "" : ": " + reason);
  const auto r = backend_.task_command(task_id, wire_kind, reason, "console:" + user->name);
  audit(*user, kind, task_id, r.ok ? "sent" : "failed: " + r.message);
  if (!r.ok) return send_error(res, 503, r.message, req.path);
  send_json(res, {{"done", kind}, {"task_id", task_id}});
}

void HttpApi::post_task_cancel(const httplib::Request& req, httplib::Response& res) {
  task_command(req, res, "cancel", Role::kProgrammer);
}

void HttpApi::post_task_pause(const httplib::Request& req, httplib::Response& res) {
  task_command(req, res, "pause", Role::kOperator);
}

void HttpApi::post_task_stop(const httplib::Request& req, httplib::Response& res) {
  task_command(req, res, "stop", Role::kOperator);
}

void HttpApi::post_prompt_answer(const httplib::Request& req, httplib::Response& res) {
  auto user = who(req, res, Role::kOperator);
  if (!user) return;
  auto b = body(req, res);
  if (!b) return;
  const std::string prompt_id = req.matches[1];
  if (!b->contains("answer") || !(*b)["answer"].is_string())
    return send_error(res, 400, "expected {\"answer\": \"<one of the prompt's options>\"}", req.path + "#/answer");
  const std::string answer = (*b)["answer"];
  const json prompt = state_.prompt(prompt_id);
  if (prompt.is_null()) {
    audit(*user, "answer", prompt_id, "refused: not open");
    return send_error(res, 409, "prompt " + prompt_id + " is not open (answered, withdrawn or unknown)", req.path);
  }
  const auto& options = prompt["options"];
  if (std::find(options.begin(), options.end(), answer) == options.end())
    return send_error(res, 400, "\"" + answer + "\" is not one of the options " + to_text(options), req.path + "#/answer");
  const auto r = backend_.answer_prompt(prompt_id, answer, user->name, text_field(*b, "comment"));
  audit(*user, "answer " + answer, prompt_id, r.ok ? "sent" : "failed: " + r.message);
  if (!r.ok) return send_error(res, 503, r.message, req.path);
  send_json(res, {{"done", "answer"}, {"prompt_id", prompt_id}, {"answer", answer}});
}

}  // namespace rigger::console
