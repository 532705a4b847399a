// The mm / cm / in choice: a select showing `current`, which keeps the choice for
// this browser and calls `onChange(unit)`.
import { setPreferredUnit, UNITS } from '../units.js';
import { h } from './dom.js';

export function unitSelect(current, onChange, label = 'Unit') {
  return h(
    'label',
    { class: 'unit-select' },
    h(
      'select',
      {
        'aria-label': label,
        onchange: (e) => {
          setPreferredUnit(e.target.value);
          onChange(e.target.value);
        },
      },
      Object.keys(UNITS).map((u) => h('option', { value: u, selected: u === current }, UNITS[u].label)),
    ),
  );
}
