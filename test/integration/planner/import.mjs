// A STEP file imported in the planner, run by planner_browser_test.cpp (the CAD service, the world model
// and the console of the simulated cell): headless Debian chromium through playwright-core. The person
// chooses a file the repository does not ship (the generated cell's flange plate, written with OpenCascade
// by the C++ side: STEP), and the page shows its units, solids, faces, holes and product tree, draws it
// beside the cell, and a click on it picks its face with the imported model's reference. A file that is
// not STEP is refused on the page with the CAD service's reason. Then it becomes a cell object by name
// and material (a taken name refused first), its bytes going with the revision, so the CAD service draws
// it from its own copy; it is placed by picks on the part fixture and its insertion into the target is
// declared by picks. Synchronisation is on the page's state,
// never a sleep; a failed check exits 1. RESULT: what the page showed.
import path from 'node:path';
import { ART, call, check, closeBrowser, viewGestures, env, launchBrowser, openPlanner, waitForDrawnRevision } from './harness.mjs';

const result = {};
const browser = await launchBrowser();
try {
  const page = await openPlanner(browser);
  const state = (fn, arg) => page.evaluate(fn, arg);
  // The walkthrough's pictures (docs/console.md, "Your own product"), in the test's artifacts.
  const picture = (name, selector) => page.locator(selector).first().screenshot({ path: path.join(ART, `your-product-${name}.png`) });
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
  await picture('1-imported', '.pview');
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
  await page.click('#planner-clear-picks');

  // --- made a cell object: a name the cell has is refused on the page, nothing committed ---
  const notice = () => page.locator('#planner-notice').innerText();
  const revisionBefore = (await call('/api/cell')).json.cell_revision;
  check(await page.locator('#planner-add-name').isVisible(), 'the page offers to add the imported part to the cell');
  await page.fill('#planner-add-name', 'part');
  await page.click('#planner-add-object');
  await page.waitForFunction(() => /^Add to the cell: /.test(document.querySelector('#planner-notice')?.textContent || ''), null, { timeout: 20000 });
  const taken = await notice();
  check(/"part" already/.test(taken), `a taken name is refused: ${taken}`);
  check((await call('/api/cell')).json.cell_revision === revisionBefore, 'nothing was committed');
  result.taken = taken;

  // --- added: its bytes go with the revision; the 3D view draws it from the CAD service's copy ---
  await page.fill('#planner-add-name', 'flange_imported');
  await page.selectOption('#planner-add-material', 'steel');
  await page.click('#planner-add-object');
  await page.waitForFunction((before) => document.querySelector('#confirm[open]')
    || (document.querySelector('#planner-notice.error') && document.querySelector('#planner-notice').textContent !== before), taken, { timeout: 30000 });
  check(await page.locator('#confirm[open]').count() === 1, `the console asked to confirm (${await notice()})`);
  await picture('2-add', '#confirm');
  const question = await page.locator('#confirm-text').innerText();
  check(/becomes the object flange_imported, loose, of steel.*added flange_imported/.test(question), `the confirmation says what changes: ${question}`);
  await page.click('#confirm-yes');
  await page.waitForFunction(() => /^Added flange_imported to the cell: cell revision \d+/.test(document.querySelector('#planner-notice')?.textContent || ''), null, { timeout: 30000 });
  result.added = await notice();
  await waitForDrawnRevision(page, Number(/cell revision (\d+)/.exec(result.added)[1]));
  await page.waitForFunction(() => window.rigger.planner.view.parts.get('flange_imported')?.features?.faces?.length > 0, null, { timeout: 60000 });
  const cellPart = await state(() => {
    const p = window.rigger.planner.view.parts.get('flange_imported');
    return { sha: p.sha256, faces: p.features.faces.length, imported: window.rigger.planner.view.parts.has('imported') };
  });
  check(cellPart.sha === drawn.sha && cellPart.faces === drawn.faces && !cellPart.imported,
    `the cell's new object is drawn from the same bytes, in place of the import ${JSON.stringify(cellPart)}`);
  const added = (await call('/api/world/entity/flange_imported')).json;
  check(added && added.kind === 'object', `the world model serves the new object ${JSON.stringify(added).slice(0, 200)}`);

  // --- placed by picks: its bottom face on the part fixture's top face, away from the part on it ---
  const { box, orbit, clickAt } = await viewGestures(page);
  const bottom = await state(() => {
    const part = window.rigger.planner.view.parts.get('flange_imported').features;
    const down = part.faces.filter((f) => f.signature?.type === 'plane' && f.signature.direction[2] < -0.99);
    const f = down.reduce((a, b) => (b.signature.centroid_m[2] < a.signature.centroid_m[2] ? b : a));
    const hole = (p) => part.holes.some((h) => Math.hypot(h.entry_m[0] - p[0], h.entry_m[1] - p[1]) < h.diameter_m);
    for (const r of [0.0, 0.02, 0.04, 0.06, 0.08]) {
      const p = [f.signature.centroid_m[0] + r, f.signature.centroid_m[1] + r / 2, f.signature.centroid_m[2]];
      if (!hole(p)) return { index: f.index, point: p, z: f.signature.centroid_m[2] };
    }
    return { index: f.index, point: f.signature.centroid_m, z: f.signature.centroid_m[2] };
  });
  await page.click('[data-frame="flange_imported"]');
  await orbit(-0.3 * box.height);
  const own = await clickAt('flange_imported', bottom.point);
  check(own.entity === 'flange_imported' && own.kind === 'face' && own.face === bottom.index,
    `the click from below picked the new object's bottom face ${bottom.index} (got ${own.entity} ${own.kind} ${own.face})`);
  await orbit(0.3 * box.height);
  await page.click('[data-frame="part_fixture"]');
  const onto = await clickAt('part_fixture', [-0.15, -0.1, 0]);
  check(onto.entity === 'part_fixture' && onto.kind === 'face', `picked the part fixture's top face (got ${onto.entity} ${onto.kind})`);
  await page.click('#planner-place-known');
  await page.click('#planner-place');
  await page.waitForFunction(() => document.querySelector('#confirm[open]') || document.querySelector('#planner-notice.error'), null, { timeout: 20000 });
  check(await page.locator('#confirm[open]').count() === 1, `the console asked to confirm the placement (${await notice()})`);
  await page.click('#confirm-yes');
  await page.waitForFunction(() => /^Placed flange_imported on part_fixture: cell revision \d+/.test(document.querySelector('#planner-notice')?.textContent || ''), null, { timeout: 20000 });
  result.placed = await notice();
  await waitForDrawnRevision(page, Number(/cell revision (\d+)/.exec(result.placed)[1]));
  await page.click('[data-frame="flange_imported"]');
  await picture('3-placed', '.pview');
  const placed = (await call('/api/world/entity/flange_imported')).json;
  const fixture = (await call('/api/world/entity/part_fixture')).json;
  const zOf = (e) => (e.world_pose || e.pose).position_m[2];
  const gap = zOf(placed) + bottom.z - zOf(fixture);
  check(Math.abs(gap) < 1e-6, `the new object's bottom face lies on the fixture's top face (gap ${gap} m)`);
  result.placed_pose = placed.world_pose || placed.pose;

  // --- its insertion declared by picks: its bottom face (the fixture hidden, seen from below) on the
  //     target's top face ---
  await page.click('#planner-clear-picks');
  await page.click('[data-part="part_fixture"]');
  await page.click('[data-frame="flange_imported"]');
  await orbit(-0.3 * box.height);
  const mating = await clickAt('flange_imported', bottom.point);
  check(mating.entity === 'flange_imported' && mating.face === bottom.index, `picked the bottom face again (got ${mating.entity} ${mating.face})`);
  await orbit(0.3 * box.height);
  await page.click('[data-part="part_fixture"]');
  await page.click('[data-frame="target"]');
  const into = await clickAt('target', [-0.1, 0.05, 0]);
  check(into.entity === 'target' && into.kind === 'face', `picked the target's top face (got ${into.entity} ${into.kind})`);
  await page.click('#planner-declare summary');
  await page.selectOption('#planner-declare-kind', 'insertion');
  await page.click('#planner-declare-submit');
  await page.waitForSelector('#confirm-yes', { state: 'visible', timeout: 20000 });
  await page.click('#confirm-yes');
  await page.waitForFunction(() => /^Declared flange_imported\/insertion/.test(document.querySelector('#planner-declare-status').textContent), null, { timeout: 30000 });
  await waitForDrawnRevision(page, Number(/cell revision (\d+)/.exec(await page.locator('#planner-declare-status').innerText())[1]));
  const inserted = (await call('/api/world/entity/flange_imported')).json;
  const insertion = inserted.features?.insertion;
  check(insertion?.target === 'target', `the world model serves the insertion into the target ${JSON.stringify(insertion)}`);
  result.insertion = insertion;
  result.bottom_z = bottom.z;

  // --- a marker on its top face: one too large for the face refused, then one that fits ---
  const declareAndConfirm = async (status) => {
    const before = await page.locator('#planner-declare-status').innerText();
    await page.click('#planner-declare-submit');
    await page.waitForFunction((b) => document.querySelector('#confirm[open]')
      || (/^Nothing declared/.test(document.querySelector('#planner-declare-status').textContent) && document.querySelector('#planner-declare-status').textContent !== b), before, { timeout: 20000 });
    check(await page.locator('#confirm[open]').count() === 1, `the console asked to confirm (${await page.locator('#planner-declare-status').innerText()})`);
    await page.click('#confirm-yes');
    await page.waitForFunction((re) => new RegExp(re).test(document.querySelector('#planner-declare-status').textContent), status, { timeout: 30000 });
    await waitForDrawnRevision(page, Number(/cell revision (\d+)/.exec(await page.locator('#planner-declare-status').innerText())[1]));
  };
  await page.click('#planner-clear-picks');
  await page.click('[data-frame="flange_imported"]');
  // Where a 40 mm marker lies whole on an upward face: its centre and four corners all pick that face.
  const spot = await state(() => {
    const planner = window.rigger.planner;
    const part = planner.view.parts.get('flange_imported').features;
    const fits = (face, p) => {
      const q = planner.screenOf('flange_imported', p);
      const hit = planner.view.pickAt(q.x, q.y);
      return hit && hit.entity === 'flange_imported' && hit.kind === 'face' && hit.face === face;
    };
    const reach = Math.max(...part.edges.map((e) => Math.max(e.signature.radius_m || 0,
      ...[e.start_m, e.end_m].map((p) => Math.hypot(p[0], p[1])))));
    for (const f of part.faces.filter((g) => g.signature?.type === 'plane' && g.signature.direction[2] > 0.99)) {
      const z = f.signature.centroid_m[2];
      for (let x = -reach; x <= reach; x += 0.01) {
        for (let y = -reach; y <= reach; y += 0.01) {
          if ([[0, 0], [-1, -1], [1, -1], [1, 1], [-1, 1]].every(([i, j]) => fits(f.index, [x + 0.025 * i, y + 0.025 * j, z])))
            return { face: f.index, point: [x, y, z] };
        }
      }
    }
    return null;
  });
  check(spot, 'an upward face has room for a 40 mm marker in view');
  const onTop = await clickAt('flange_imported', spot.point);
  check(onTop.kind === 'face' && onTop.face === spot.face, `picked the new object's upward face ${spot.face} (got ${onTop.kind} ${onTop.face})`);
  await page.selectOption('#planner-declare-kind', 'marker');
  await page.selectOption('#planner-declare-dictionary', 'DICT_4X4_50');
  await page.fill('#planner-declare-marker-id', '30');  // 20 is the part's
  await page.fill('#planner-declare-marker-size', '600');
  const revisionNow = (await call('/api/cell')).json.cell_revision;
  await page.click('#planner-declare-submit');
  await page.waitForFunction(() => /^Nothing declared/.test(document.querySelector('#planner-declare-status').textContent), null, { timeout: 20000 });
  const tooLarge = await page.locator('#planner-declare-status').innerText();
  check(/does not fit on face/.test(tooLarge) && /#\/size_m/.test(tooLarge), `a marker larger than its face is refused at /size_m: ${tooLarge}`);
  check((await call('/api/cell')).json.cell_revision === revisionNow, 'nothing was committed');
  result.marker_too_large = tooLarge;
  await page.fill('#planner-declare-marker-size', '40');
  await picture('4-marker', '#planner-declare');
  await declareAndConfirm('^Declared flange_imported/marker 30');

  // --- the rope attachment at one of its holes ---
  await page.click('#planner-clear-picks');
  const holeEntry = await state(() => window.rigger.planner.view.parts.get('flange_imported').features.holes
    .find((h) => h.axis[2] > 0.99).entry_m);
  const atHole = await state((p) => window.rigger.planner.screenOf('flange_imported', p), holeEntry);
  await page.mouse.click(atHole.x, atHole.y);
  await page.waitForFunction(() => window.rigger.planner.state.picks.length === 1, null, { timeout: 10000 });
  const holePick = await state(() => window.rigger.planner.state.picks[0]);
  check(holePick.kind === 'hole', `picked a hole of the new object (got ${holePick.kind})`);
  await page.selectOption('#planner-declare-kind', 'rope_attachment');
  await declareAndConfirm('^Declared flange_imported/rope_attachment');
  const served = (await call('/api/world/entity/flange_imported')).json.features;
  check(served.markers?.items?.some((m) => m.id === 30 && m.size_m === 0.04), `the world model serves the marker ${JSON.stringify(served.markers)}`);
  check(served.rope_attachment, `the world model serves the rope attachment ${JSON.stringify(served.rope_attachment)}`);
  result.marker = served.markers;
  result.rope_attachment = served.rope_attachment;
  result.hole_entry = holeEntry;
  result.revision_before = revisionBefore;
  result.revision_after = (await call('/api/cell')).json.cell_revision;

  // --- one of the cell's own models imported again, for a second object of the same part ---
  const listed = await state(() => [...document.querySelectorAll('#planner-cell-model option')].map((o) => ({ value: o.value, text: o.textContent })));
  const mine = listed.find((o) => o.value === drawn.sha);
  check(mine && /flange_imported/.test(mine.text), `the cell's models list the added part's model ${JSON.stringify(listed)}`);
  await page.selectOption('#planner-cell-model', drawn.sha);
  await page.click('#planner-import-cell-model');
  await page.waitForFunction((sha) => window.rigger.planner.view.parts.get('imported')?.sha256 === sha, drawn.sha, { timeout: 30000 });
  const again = await page.locator('#planner-imported-summary').innerText();
  check(again.includes(drawn.sha.slice(0, 12)) && /^flange_imported\.step: /.test(again), `imported again from the cell's copy: ${again}`);
  result.imported_from_cell = again;

  // --- an assembly: its sub-assembly "frame" chosen in the product tree by the keyboard, drawn
  //     highlighted in the faint file, added alone under its own name ---
  const assemblyStarted = Date.now();
  await imported(env('ASSEMBLY'));
  const nodes = await page.$$eval('.product-tree .product-node', (bs) => bs.map((b) => ({ path: b.dataset.path, text: b.textContent })));
  check(JSON.stringify(nodes.map((n) => n.path)) === JSON.stringify(['', '0', '0/0', '0/1', '1', '1/0', '1/1', '2']),
    `each node of the product tree is a button with its path ${JSON.stringify(nodes)}`);
  check(/^block — instance block_left$/.test(nodes[5].text) && /^block — instance block_right$/.test(nodes[6].text),
    `the part used twice is two nodes, by instance ${JSON.stringify(nodes.slice(5))}`);
  const file = await state(() => window.rigger.planner.importer.imported.model);
  // The sheet (one face, no solid) cannot be an object: the page says why, and the whole file stays chosen.
  await page.click('.product-node[data-path="2"]');
  await page.waitForFunction(() => /holds no solid/.test(document.querySelector('#planner-notice')?.textContent || ''), null, { timeout: 60000 });
  const sheet = await state(() => ({ notice: document.querySelector('#planner-notice').textContent,
    chosen: window.rigger.planner.importer.chosen, pressed: document.querySelector('.product-node[data-path="2"]').getAttribute('aria-pressed'),
    whole: document.querySelector('.product-node[data-path=""]').getAttribute('aria-pressed') }));
  check(/^sheet — instance sheet_1: .*node 2 \('sheet'\) holds no solid: only a solid can be an object/.test(sheet.notice) &&
    sheet.chosen === null && sheet.pressed === 'false' && sheet.whole === 'true',
    `a node without a solid is refused saying why, nothing chosen ${JSON.stringify(sheet)}`);
  result.sheet_refused = sheet.notice;
  await page.focus('.product-node[data-path="0"]');
  await page.keyboard.press('Enter');
  await page.waitForFunction(() => /^Chosen: frame/.test(document.querySelector('#planner-imported-node')?.textContent || ''), null, { timeout: 60000 });
  await page.waitForFunction(() => window.rigger.planner.view.parts.get('imported')?.color !== undefined, null, { timeout: 60000 });
  const chosenText = await page.locator('#planner-imported-node').innerText();
  check(/: 2 solids, \d+ faces, 5 holes, drawn highlighted/.test(chosenText), `the page says what the node holds: ${chosenText}`);
  const chosen = await state(() => {
    const v = window.rigger.planner.view, node = v.parts.get('imported'), whole = v.parts.get('imported-file');
    const p = (part) => { part.group.updateMatrixWorld(true); return part.group.position.toArray(); };
    return { sha: node.sha256, holes: node.features.holes.length, ghost: Boolean(whole?.ghost), at: p(node), file_at: whole && p(whole),
      pressed: document.querySelector('.product-node[data-path="0"]').getAttribute('aria-pressed'),
      name: document.querySelector('#planner-add-name').value };
  });
  check(`sha256:${chosen.sha}` !== file && chosen.holes === 5 && chosen.ghost && chosen.pressed === 'true',
    `the node is drawn from a model of its own, the file faint around it ${JSON.stringify(chosen)}`);
  const offset = chosen.at.map((x, i) => x - chosen.file_at[i]);
  check(Math.hypot(offset[0] - 1, offset[1], offset[2]) < 1e-9, `the node is drawn where the file has it (1 m along x): ${offset}`);
  check(chosen.name === 'frame', `the object's name is proposed from the node's: ${chosen.name}`);
  await picture('5-tree', '#planner-imported');
  await picture('6-node', '.pview');
  await page.selectOption('#planner-add-material', 'aluminium');
  await page.click('#planner-add-object');
  await page.waitForSelector('#confirm[open]', { timeout: 30000 });
  await page.click('#confirm-yes');
  await page.waitForFunction(() => /^Added frame to the cell: cell revision \d+/.test(document.querySelector('#planner-notice')?.textContent || ''), null, { timeout: 30000 });
  const frameAdded = await notice();
  await waitForDrawnRevision(page, Number(/cell revision (\d+)/.exec(frameAdded)[1]));
  const frameWorld = (await call('/api/world/entity/frame')).json;
  const frameFeatures = (await call('/api/cad/features?model=object%3Aframe')).json;
  const frameModels = (await call('/api/planner/cell_models')).json.filter((m) => m.name === 'imported/frame.step');
  check(frameModels.length === 1 && frameModels[0].sha256 === chosen.sha, `the revision pins the node's own file ${JSON.stringify(frameModels)}`);
  result.assembly = { file, node_sha256: chosen.sha, chosen: chosenText, size_m: frameWorld.model?.size_m,
    holes: frameFeatures.holes.map((h) => ({ entry_m: h.entry_m, diameter_m: h.diameter_m })), added: frameAdded,
    seconds: (Date.now() - assemblyStarted) / 1000 };
} finally {
  await closeBrowser(browser, result);
}
