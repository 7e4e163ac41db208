// A STEP file imported in the planner, run by planner_browser_test.cpp (the CAD service, the world model
// and the console of the simulated cell): headless Debian chromium through playwright-core. The person
// chooses a file the repository does not ship (the generated cell's flange plate, written with OpenCascade
// by the C++ side: STEP), and the page shows its units, solids, faces, holes and product tree, draws it
// beside the cell, and a click on it picks its face with the imported model's reference. A file that is
// not STEP is refused on the page with the CAD service's reason. Synchronisation is on the page's state,
// never a sleep; a failed check exits 1. RESULT: what the page showed.
import { check, closeBrowser, env, launchBrowser, openPlanner } from './harness.mjs';

const result = {};
const browser = await launchBrowser();
try {
  const page = await openPlanner(browser);
  const state = (fn, arg) => page.evaluate(fn, arg);
  const imported = async (file) => {
    await page.setInputFiles('#planner-import', file);
    await page.waitForFunction(() => {
      const t = document.querySelector('#planner-imported')?.textContent || '';
      return !/^Reading/.test(t) && (document.querySelector('#planner-imported-summary') || document.querySelector('#planner-import-error'));
    }, null, { timeout: 60000 });
  };

  // --- not a STEP file: refused with the reason, nothing drawn ---
  await imported(env('NOT_STEP'));
  const error = await page.locator('#planner-import-error').innerText();
  check(/CAD_/.test(error), `a file that is not STEP is refused with the CAD service's code: ${error}`);
  check(!(await state(() => window.rigger.planner.view.parts.has('imported'))), 'nothing is drawn for it');
  result.error = error;

  // --- the flange: what it holds, drawn beside the cell ---
  await imported(env('FLANGE'));
  const summary = await page.locator('#planner-imported-summary').innerText();
  check(/^flange\.step: units m, \d+ solids?, \d+ faces, 6 holes/.test(summary), `the page says what the file holds: ${summary}`);
  const products = await page.$$eval('.product-tree li', (lis) => lis.map((li) => li.dataset.product));
  check(products.includes('flange'), `the product tree names the part: ${JSON.stringify(products)}`);
  await page.waitForFunction(() => window.rigger.planner.view.parts.has('imported'), null, { timeout: 60000 });
  const drawn = await state(() => {
    const p = window.rigger.planner.view.parts.get('imported');
    return p && { faces: p.features.faces.length, sha: p.sha256, model: window.rigger.planner.importer.imported.model };
  });
  check(drawn && `sha256:${drawn.sha}` === drawn.model, `the 3D view draws the imported model ${JSON.stringify(drawn)}`);
  check(summary.includes(`${drawn.faces} faces`), `the drawing has the file's ${drawn.faces} faces`);
  result.summary = summary;
  result.products = products;
  result.model = drawn.model;

  // --- a click on its top face picks it, with the imported model's reference ---
  const top = await state(() => window.rigger.planner.view.parts.get('imported').features.faces
    .filter((f) => f.signature?.type === 'plane' && f.signature.direction[2] > 0.99)
    .reduce((a, b) => (b.signature.centroid_m[2] > a.signature.centroid_m[2] ? b : a)));
  // Off the centroid: the plate's centre may be a hole.
  const at = await state((f) => {
    const faces = window.rigger.planner.view.parts.get('imported').features;
    const hole = (p) => faces.holes.some((h) => Math.hypot(h.entry_m[0] - p[0], h.entry_m[1] - p[1]) < h.diameter_m);
    for (const r of [0.0, 0.02, 0.04, 0.06, 0.08]) {
      const p = [f.signature.centroid_m[0] + r, f.signature.centroid_m[1] + r / 2, f.signature.centroid_m[2]];
      if (!hole(p)) return p;
    }
    return f.signature.centroid_m;
  }, top);
  const q = await state((p) => window.rigger.planner.screenOf('imported', p), at);
  await page.mouse.click(q.x, q.y);
  await page.waitForFunction(() => window.rigger.planner.state.picks.length === 1, null, { timeout: 10000 });
  const pick = await state(() => window.rigger.planner.state.picks[0]);
  check(pick.entity === 'imported' && pick.kind === 'face' && pick.face === top.index && pick.ref.model_sha256 === drawn.sha,
    `the click picked the imported model's top face ${top.index} (${pick.entity} ${pick.kind} ${pick.face})`);
  const hint = await page.locator('#planner-place-hint').innerText();
  check(/not a part of the cell yet/.test(hint), `Place says the imported file is not a cell part yet: ${hint}`);
  result.pick = { face: pick.face, sha256: pick.ref.model_sha256 };
} finally {
  await closeBrowser(browser, result);
}
