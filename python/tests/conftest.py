# The Python tests: `-m "not slow"` is the fast label of ctest (python_fast), `-m slow` the rest.
def pytest_configure(config):
    config.addinivalue_line("markers", "slow: takes more than a second or two (ctest label slow)")
