// The planner's editing errors in a real browser (target: "editing errors are shown on the right node
// and field, and publishing is refused"), run by planner_browser_test.cpp with the same services as
// e2e.mjs. One tree built by clicks holds three errors the controller's validator finds: a Parallel
// whose success threshold (3) exceeds its two branches, those two branches both claiming the robot and
// the gripper (Release of the load, Release of the target), and an InsertVisuallyGuided whose
// preconditions nothing before it provides. Each is checked on its node (the ⚠ mark), on its field or
// the form's condition or resource it names, and in the list; axe-core runs with the errors shown; then
// Publish is clicked and must be refused in the page, with no confirmation asked and no task at the
// console. Any failed check ends the script with exit code 1.
import path from 'node:path';
import { ART, MODULES, call, check, closeBrowser, launchBrowser, openPlanner, waitForSkills } from './harness.mjs';

const TASK = 'planned-errors';
const INSERT = '/root/children/0';
const PARALLEL = '/root/children/1';
const SECOND_BRANCH = '/root/children/1/children/1';
const result = { task_id: TASK };
await waitForSkills(['Release', 'InsertVisuallyGuided']);

const browser = await launchBrowser();
try {
  const page = await openPlanner(browser);
  const addNode = async (value) => { await page.selectOption('#planner-add-kind', value); await page.click('#planner-add'); };
  const select = async (pointer) => page.click(`button.pnode[data-pointer="${pointer}"]`);
  const selected = () => page.evaluate(() => window.rigger.planner.state.selected);

  // --- the tree, by clicks ---
  await page.fill('#planner-task-id', TASK);
  await addNode('control:Sequence');
  await addNode('skill:InsertVisuallyGuided');    // first: nothing localizes or attaches anything before it
  check(await selected() === INSERT, 'the InsertVisuallyGuided is the Sequence\'s first child');
  await select('/root');
  await addNode('control:Parallel');
  check(await selected() === PARALLEL, 'the Parallel is the Sequence\'s second child');
  await addNode('skill:Release');                 // object: the default, the load
  await select(PARALLEL);
  await addNode('skill:Release');
  check(await selected() === SECOND_BRANCH, 'the second Release is the Parallel\'s second branch');
  await page.selectOption('#param-object', 'target');
  await select(PARALLEL);
  await page.fill('[data-field="success_threshold"]', '3');  // 3 successes needed of 2 branches

  // --- wait for the validation of this tree: the three errors, by the controller's validator ---
  await page.waitForFunction(([par, branch, ins]) => {
    const s = window.rigger.planner.state;
    const errs = s.errors || [];
    return s.validated === s.validations
      && errs.some((e) => e.pointer === `${par}/success_threshold`)
      && errs.some((e) => e.pointer === branch && /^resources? .*claimed/.test(e.message))
      && errs.some((e) => e.pointer === ins && e.message.startsWith('precondition "localized(target)"'));
  }, [PARALLEL, SECOND_BRANCH, INSERT], { timeout: 20000 });
  const errors = await page.evaluate(() => window.rigger.planner.state.errors);
  result.errors = errors;
  console.log(`ok: the validator's errors: ${errors.map((e) => `${e.pointer}: ${e.message}`).join('\n    ')}`);
  const invalidNodes = await page.$$eval('button.pnode.invalid', (bs) => bs.map((b) => b.dataset.pointer));
  result.invalid_nodes = invalidNodes;
  check(JSON.stringify([...invalidNodes].sort()) === JSON.stringify([PARALLEL, SECOND_BRANCH, INSERT].sort()),
    `exactly the Parallel, its second branch and the insertion are flagged (flagged: ${invalidNodes})`);
  const listed = await page.$$eval('#planner-errors li button', (bs) => bs.map((b) => b.textContent));
  check([`${PARALLEL}/success_threshold`, SECOND_BRANCH, INSERT].every((p) => listed.includes(p)), `the list names each error's pointer: ${listed}`);
  check(await page.locator('#planner-valid').count() === 0, 'the page does not say valid');
  await page.addScriptTag({ path: path.join(MODULES, 'axe-core/axe.min.js') });
  const axe = () => page.evaluate(async () => (await window.axe.run(document)).violations.map((x) => `${x.id}: ${x.help} (${x.nodes.length}: ${x.nodes.map((n) => n.target).join(' ')})`));
  /// The form's own display of the selected node's errors: per field, the node-level text, the marks.
  const form = () => page.evaluate(() => ({
    fields: Object.fromEntries([...document.querySelectorAll('.pform [data-field][aria-invalid="true"]')].map((f) =>
      [f.dataset.field, f.closest('.field').querySelector('.field-error').textContent])),
    node: document.querySelector('.pform .node-errors')?.textContent || '',
    unmet: [...document.querySelectorAll('.pform [data-conditions="preconditions"] code.unmet')].map((c) => c.textContent.trim()),
    claims: [...document.querySelectorAll('.pform code[data-claim].unmet')].map((c) => c.textContent.trim()),
  }));

  // --- (1) the impossible threshold: on the Parallel and its success_threshold field ---
  await select(PARALLEL);
  let f = await form();
  check(Object.keys(f.fields).join() === 'success_threshold' && /success_threshold/.test(f.fields.success_threshold),
    `the Parallel's form flags its success_threshold field with the validator's message ${JSON.stringify(f)}`);
  result.threshold = { node: PARALLEL, field: 'success_threshold', message: f.fields.success_threshold };
  let violations = await axe();
  check(violations.length === 0, `axe-core: no violations with the threshold error shown ${JSON.stringify(violations)}`);

  // --- (2) two branches claiming the robot: on the later branch, its claimed resources marked ---
  await select(SECOND_BRANCH);
  f = await form();
  check(/resources "gripper", "robot" are claimed both by Skill Release at \/root\/children\/1\/children\/1 and by Skill Release at \/root\/children\/1\/children\/0, which run concurrently under the Parallel at \/root\/children\/1/.test(f.node),
    `the second Release's form shows the resource conflict ${JSON.stringify(f)}`);
  check(JSON.stringify([...f.claims].sort()) === '["gripper","robot"]' && Object.keys(f.fields).length === 0,
    `the robot and the gripper are marked among its resources, not the target, and no field ${JSON.stringify(f)}`);
  result.conflict = { node: SECOND_BRANCH, claims: f.claims, message: f.node };
  await select(`${PARALLEL}/children/0`);
  f = await form();
  check(f.node === '' && f.claims.length === 0, `the first Release (claimed first) is not flagged ${JSON.stringify(f)}`);

  // --- (3) preconditions nothing provides: on the insertion, the unmet conditions marked ---
  await select(INSERT);
  f = await form();
  const unmet = [...f.unmet].sort();
  check(JSON.stringify(unmet) === '["attached(robot,load)","localized(load)","localized(target)"]',
    `the insertion's form marks each unmet precondition ${JSON.stringify(f)}`);
  check(unmet.every((c) => f.node.includes(`precondition "${c}" of Skill InsertVisuallyGuided may not hold`)) && Object.keys(f.fields).length === 0,
    `the form shows the validator's message for each, on no field ${JSON.stringify(f)}`);
  result.preconditions = { node: INSERT, unmet, message: f.node };
  violations = await axe();
  check(violations.length === 0, `axe-core: no violations with the precondition errors shown ${JSON.stringify(violations)}`);
  await page.screenshot({ path: path.join(ART, 'planner-errors.png'), fullPage: true });

  // --- Publish is refused: a message, no confirmation dialog, nothing at the console ---
  await page.click('#planner-publish');
  await page.waitForFunction(() => /^Not published/.test(document.querySelector('#planner-notice')?.textContent || ''), null, { timeout: 20000 });
  const notice = await page.locator('#planner-notice').innerText();
  result.publish_notice = notice;
  check(/validation error/.test(notice) && await page.locator('#planner-notice.error').count() === 1, `the refusal says why, as an error: ${notice}`);
  check(await page.locator('dialog[open]').count() === 0, 'no confirmation is asked');
  const st = await call('/api/state');
  check(st.status === 200 && !JSON.stringify(st.json?.tasks ?? []).includes(TASK), `the console knows no task ${TASK}: ${JSON.stringify(st.json?.tasks)}`);
  result.tasks_at_console = st.json?.tasks ?? null;
  console.log(`ok: publishing refused: ${notice}`);
} finally {
  await closeBrowser(browser, result);
}
