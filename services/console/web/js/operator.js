// The operator station: the open prompts, the screw prompt's hole in 3D, the answer buttons (each
// confirmed), and a Stop that is always on screen. Large touch targets throughout.
import { api, store, el, confirmDialog } from './api.js';

const TERMINAL = new Set(['SUCCEEDED', 'FAILED', 'CANCELED', 'REJECTED']);

export function operatorPage(main, me) {
  const canAnswer = me.role === 'operator' || me.role === 'programmer';
  const viewBox = el('div', { class: 'view', role: 'img', 'aria-label': 'The target part with the prompted screw hole' });
  const badge = el('div', { class: 'badge', 'aria-hidden': 'true' });
  viewBox.append(badge);
  const panel = el('section', { class: 'panel prompt', 'aria-live': 'polite', 'aria-labelledby': 'prompt-title' });
  const others = el('ul', { 'aria-label': 'Other open prompts' });
  const notice = el('p', { role: 'status', 'aria-live': 'assertive' });
  const stop = el('button', { class: 'danger big', id: 'stop', onclick: () => stopAll(), disabled: !canAnswer }, '■ Stop');
  main.replaceChildren(el('h1', {}, 'Operator station'), el('div', { class: 'stopbar' }, stop), notice,
    el('div', { class: 'op' }, viewBox, el('div', {}, panel, el('section', { class: 'panel' }, el('h2', {}, 'Open prompts'), others))));
  const pageState = { prompt_id: '', hole: '', answered: [] };
  window.rigger.operator = pageState;
  let view = null;
  let viewReady = null;
  const say = (text, bad = false) => { notice.textContent = text; notice.className = bad ? 'error' : ''; };

  // The part in the 3D view: the one owning the prompted hole. Loads run one after another, so the part
  // asked for last is the one shown; without a prompt yet, "target" (the shipped cell's).
  let viewEntity = null;
  async function ensureView(entity) {
    if (!viewReady) {
      viewReady = import('./view3d.js').then(({ TargetView }) => {
        view = new TargetView(viewBox);
        window.rigger.view3d = view.state;
      });
    }
    if (entity === undefined && viewEntity !== null) return viewReady;
    const wanted = entity ?? 'target';
    if (wanted === viewEntity) return viewReady;
    viewEntity = wanted;
    viewReady = viewReady.then(async () => {
      if (viewEntity !== wanted) return;  // a later prompt asked for another part meanwhile
      try { await view.load(wanted); view.state.entity = wanted; } catch (e) { view.state.error = e.message; say(`3D view: ${e.message}`, true); }
    });
    return viewReady;
  }

  async function stopAll() {
    const live = [...store.tasks.values()].filter((t) => !TERMINAL.has(t.state));
    if (!live.length) return say('No task is running.');
    for (const t of live) {
      try { await api(`/api/tasks/${encodeURIComponent(t.task_id)}/stop`, { method: 'POST', body: { reason: 'Stop pressed at the operator station' } }); say(`Stop sent for ${t.task_id}.`); } catch (e) { say(`Stop ${t.task_id}: ${e.message}`, true); }
    }
  }

  async function answer(p, option) {
    const hole = p.details?.hole_ref || p.details?.hole || '';
    if (!(await confirmDialog(`Answer “${option}”?`, `${p.title}${hole ? ` — hole ${hole}` : ''}: answer “${option}”.`, option.charAt(0).toUpperCase() + option.slice(1)))) return;
    try {
      await api(`/api/prompts/${encodeURIComponent(p.prompt_id)}/answer`, { method: 'POST', body: { answer: option } });
      pageState.answered.push({ prompt_id: p.prompt_id, answer: option });
      say(`Answered “${option}” to ${p.title}.`);
    } catch (e) { say(`${p.title}: ${e.message}`, true); }
  }

  function current() {
    const open = [...store.prompts.values()].sort((a, b) => a.stamp - b.stamp);
    return [open[0], open.slice(1)];
  }

  async function draw() {
    const [p, rest] = current();
    others.replaceChildren(...(rest.length ? rest.map((o) => el('li', {}, o.title)) : [el('li', { class: 'muted' }, 'none')]));
    if (!p) {
      pageState.prompt_id = ''; pageState.hole = '';
      panel.replaceChildren(el('h2', { id: 'prompt-title' }, 'No open prompt'), el('p', { class: 'muted' }, 'Prompts for you appear here as the task reaches them.'));
      badge.textContent = '';
      if (view) view.highlight('');
      return;
    }
    const d = p.details || {};
    const step = /\((\d+)\/(\d+)\)/.exec(p.title || '');
    pageState.prompt_id = p.prompt_id;
    pageState.hole = d.hole || '';
    const facts = el('dl', { class: 'facts' });
    const fact = (k, v) => { if (v !== undefined && v !== '') facts.append(el('dt', {}, k), el('dd', {}, String(v))); };
    if (step) fact('Step', `${step[1]} of ${step[2]}`);
    fact('Hole', d.hole_ref || d.hole);
    fact('Screw', d.screw_type);
    fact('Length', d.length_mm ? `${d.length_mm} mm` : (/x(\d+)/.exec(d.screw_type || '')?.[1] ? `${/x(\d+)/.exec(d.screw_type)[1]} mm` : ''));
    fact('Torque', d.torque_nm !== undefined ? `${d.torque_nm} N·m` : '');
    fact('Task', p.task_id);
    const buttons = (p.options || []).map((o) => el('button', {
      class: `big ${o === 'done' ? 'primary' : o === 'failed' || o === 'abort' ? 'danger' : 'secondary'}`,
      'data-answer': o, disabled: !canAnswer, onclick: () => answer(p, o) }, o.charAt(0).toUpperCase() + o.slice(1)));
    panel.replaceChildren(...[el('h2', { id: 'prompt-title' }, p.title), el('p', {}, p.text), facts,
      canAnswer ? null : el('p', { class: 'muted' }, `You are logged in as a ${me.role}: answering needs an operator.`),
      el('div', { class: 'answers' }, ...buttons)].filter(Boolean));
    badge.innerHTML = '';
    if (p.kind === 'screw' || d.hole) {
      badge.append(el('div', {}, `${step ? `Step ${step[1]} of ${step[2]} · ` : ''}hole ${d.hole_ref || d.hole}`),
        el('div', {}, `${d.screw_type || ''} · ${d.torque_nm ?? '?'} N·m`));
      // The hole's part: "target/h1" names entity "target".
      await ensureView((d.hole_ref || '').includes('/') ? d.hole_ref.split('/')[0] : 'target');
      if (view) view.highlight(d.hole);
    }
  }

  draw();
  ensureView();
  const off = store.on((type) => { if (type === 'prompt' || type === 'load') draw(); });
  return off;
}
