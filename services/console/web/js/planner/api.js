// The console's endpoints the planner calls (docs/console.md, "Endpoints"): one function each, resolving
// to the console's JSON answer or rejecting with its ApiError (the HTTP status and the console's message).
import { api } from '../api.js';

const post = (path, body) => api(path, { method: 'POST', body });

/// The live skill library: {skills, executors, problems}.
export const skillLibrary = () => api('/api/skills');
/// The controller's validator on `recipe`: {ok, errors: [{pointer, message}], canonical}.
export const validateRecipe = (recipe) => post('/api/planner/validate', recipe);
/// The screw list of picked holes ({model, holes}), derived by the CAD service.
export const deriveScrews = (request) => post('/api/planner/screws', request);
/// A pose from picks by a CAD frame rule ({model, rule, …}): {model, model_sha256, args, pose}.
export const deriveFrame = (request) => post('/api/planner/frame', request);
/// Runs `recipe` on the rehearsal cell: {task_id, domain, state}; or, when the console is starting the
/// rehearsal cell first (nothing sent): {starting: true, task_id, domain, cell}.
export const rehearseRecipe = (recipe) => post('/api/planner/rehearse', recipe);
/// The rehearsal cell the console starts on demand: {phase, error, log, pid, domain, start_timeout_s, …}.
export const rehearsalCell = () => api('/api/rehearsal/cell');
/// The first of publishing's two steps: {confirmation_id}.
export const submitRecipe = (recipe) => post('/api/recipes', recipe);
/// The second step, once the programmer confirmed.
export const confirmCommand = (confirmationId) => post('/api/confirm', { confirmation_id: confirmationId });
