from setuptools import find_packages, setup

package_name = 'ship_mission'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    # Files the modules read beside themselves: the Fast DDS loopback profile (processes).
    package_data={package_name: ['fastdds_loopback.xml']},
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Ship Navigation Maintainers',
    maintainer_email='maintainers@shipnav.org',
    description=('Scenarios and missions: the launcher that runs a scenario as a graph of node '
                 'processes, the bag recorder, metrics, plots, reports and the live bridge.'),
    license='MIT',
    entry_points={
        'console_scripts': [
            'run_mission = ship_mission.cli:main',
            'component_container = ship_mission.container:main',
        ],
    },
)
