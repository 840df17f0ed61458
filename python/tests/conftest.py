# The Python tests: `-m "not slow"` is the fast label of ctest (python_fast), `-m slow` the rest.
import signal

# Ctrl-C tests send SIGINT and expect KeyboardInterrupt. A shell starts a background job with
# SIGINT ignored (`cmd &`, nohup), and Python then installs no handler of its own: restore
# Python's, here and (through the environment's default) in the children the tests start.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


def pytest_configure(config):
    config.addinivalue_line("markers", "slow: takes more than a second or two (ctest label slow)")
