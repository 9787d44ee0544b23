from glob import glob

from setuptools import find_packages, setup

package_name = 'ship_planner'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/config', glob('config/*.yaml')),
        ('share/' + package_name + '/config/routes', glob('config/routes/*.yaml')),
        ('share/' + package_name + '/doc', glob('doc/*.md')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Ship Navigation Maintainers',
    maintainer_email='maintainers@shipnav.org',
    description=('Route construction (waypoints, arcs, fillets, parametric curves), chart-based optimal routes, '
                 'and the route node.'),
    license='MIT',
    entry_points={
        'console_scripts': [
            'route_node = ship_planner.route_node:main',
            'planner_node = ship_planner.planner_node:main',
        ],
    },
)
