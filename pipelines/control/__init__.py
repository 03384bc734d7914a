"""Closed-loop control: camera model, attitude history, direction filter, PID, rate controllers.

Import from the modules themselves: the package loads nothing, so that a light module such as
``limits`` does not bring in the controllers' numpy and filterpy."""
