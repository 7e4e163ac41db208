// The console's pages behind one hash router: #/tasks, #/replay[/task], #/plots[/task], #/operator, #/planner.
import { api, store, token, el } from './api.js';
import { tasksPage } from './tasks.js';
import { replayPage } from './replay.js';
import { plotsPage } from './plots.js';
import { operatorPage } from './operator.js';
import { plannerPage } from './planner/page.js';

const pages = { tasks: tasksPage, replay: replayPage, plots: plotsPage, operator: operatorPage, planner: plannerPage };
const main = document.getElementById('page');
let leave = null;

function route(me) {
  const [name, ...args] = (location.hash.replace(/^#\/?/, '') || 'tasks').split('/');
  const page = pages[name] ? name : 'tasks';
  for (const a of document.querySelectorAll('header nav a')) {
    if (a.dataset.page === page) a.setAttribute('aria-current', 'page'); else a.removeAttribute('aria-current');
  }
  if (leave) leave();
  document.title = `${document.querySelector(`header nav a[data-page=${page}]`).textContent} · rigger console`;
  leave = pages[page](main, me, args);
}

async function boot() {
  if (!token()) {
    main.replaceChildren(el('h1', {}, 'Log in'), el('p', {}, 'Open the login link that the console\'s setup (or rigger-compose demo) printed: it carries your token.'));
    return;
  }
  let me;
  try {
    me = await api('/api/me');
  } catch (e) {
    main.replaceChildren(el('h1', {}, 'Not logged in'), el('p', { class: 'error' }, e.message));
    return;
  }
  document.getElementById('who').textContent = `${me.user} (${me.role})`;
  window.rigger.me = me;
  await store.connect();
  window.addEventListener('hashchange', () => route(me));
  route(me);
  window.rigger.ready = true;
}
boot();
