// ESLint for the UI's plain ES modules: the recommended set plus rules that find
// bugs rather than enforce a style (formatting is left alone). `npm run lint`
// runs it with no warnings allowed. src/ runs in the browser; the tests, the
// benchmark, the scripts and the config files run under Node.js.
import js from '@eslint/js';
import globals from 'globals';

export default [
  { ignores: ['dist/', 'node_modules/', 'test-results/'] },
  js.configs.recommended,
  {
    // The bundle's target (vite.config.js).
    languageOptions: { ecmaVersion: 2022, sourceType: 'module' },
    linterOptions: { reportUnusedDisableDirectives: 'error' },
    rules: {
      'no-unused-vars': ['error', { args: 'after-used' }],
      eqeqeq: ['error', 'always'],
      'no-shadow': ['error', { builtinGlobals: false, hoist: 'functions' }],
      'prefer-const': ['error', { destructuring: 'all' }],
      'no-var': 'error',
      'no-implicit-globals': 'error',
      'no-self-compare': 'error',
      'no-template-curly-in-string': 'error',
      'no-unmodified-loop-condition': 'error',
      'no-unreachable-loop': 'error',
      'array-callback-return': 'error',
      'no-new-wrappers': 'error',
      'no-throw-literal': 'error',
      radix: 'error',
    },
  },
  {
    files: ['src/**/*.js'],
    languageOptions: { globals: globals.browser },
  },
  {
    files: ['tests/**/*.mjs', 'bench/**/*.mjs', 'scripts/**/*.mjs', '*.config.js'],
    languageOptions: { globals: globals.node },
  },
  {
    // The functions these hand to Playwright's page.evaluate and waitForFunction
    // run in the page, where these names exist.
    files: ['tests/e2e/**/*.mjs', 'bench/**/*.mjs'],
    languageOptions: { globals: { document: 'readonly', window: 'readonly', Image: 'readonly' } },
  },
];
