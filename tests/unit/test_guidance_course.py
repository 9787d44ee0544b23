"""The course law of ship_guidance.guidance: a heading by time schedule, as a guidance law."""
import math

import pytest

from ship_guidance.guidance import Guidance, course_schedule_for, parse_course_schedule
from ship_guidance.path import Line, Route

ROUTE = Route([Line((0.0, 0.0), (1000.0, 0.0))])   # NED: 1 km north


def test_course_law_follows_the_schedule_and_keeps_the_route_metrics():
    course = Guidance(ROUTE, law='course', lookahead=100.0,
                      course_schedule=parse_course_schedule([0.0, 90.0, 10.0, 180.0]))
    los = Guidance(ROUTE, law='los', lookahead=100.0)
    for t, expected in ((0.0, 90.0), (9.9, 90.0), (10.0, 180.0)):
        a = course.update(100.0 * t, 20.0, 0.0, 0.1, t=t)
        b = los.update(100.0 * t, 20.0, 0.0, 0.1)
        assert a.heading_cmd == math.radians(expected)
        assert (a.cross_track, a.s, a.leg_index, a.finished) == (b.cross_track, b.s, b.leg_index,
                                                                 b.finished)
    assert not course.reports_completion and los.reports_completion


def test_course_law_needs_its_schedule_and_the_time():
    with pytest.raises(ValueError, match='course_schedule'):
        Guidance(ROUTE, law='course')
    with pytest.raises(ValueError, match='course_schedule'):
        Guidance(ROUTE, law='los', course_schedule=([0.0], [0.0]))
    g = Guidance(ROUTE, law='course', course_schedule=([0.0], [0.0]))
    with pytest.raises(ValueError, match='sim time'):
        g.update(0.0, 0.0)


def test_schedule_for_a_law():
    assert course_schedule_for('ilos', []) is None
    with pytest.raises(ValueError, match="empty unless law is 'course'"):
        course_schedule_for('ilos', [0.0, 90.0])
    assert course_schedule_for('course', [0.0, 90.0]) == ([0.0], [math.radians(90.0)])
